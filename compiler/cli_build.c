/* cli_build.c — `splatc build SCENE.sg -o PACKDIR [options]`, the
 * command-line face of splat_build (build.c); the options are the table
 * `options` below (splatc build --help).  Exit status 0 on success, 1 on
 * input errors, 2 on usage errors. */
#include "cli.h"
#include "args.h"
#include "scene.h"
#include "util.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifdef SPLATC_DEVICE_BAKE   /* the runtime is built: it bakes on a device */
#include "splatrt.h"
#endif

static void print_stats(const splat_build_stats *st, FILE *out)
{
    static const char *const names[] = {"load", "analysis", "compose+codegen",
                                        "glslang", "validation", "far atlas", "write"};
    double t[] = {st->load, st->analysis, st->compose, st->glslang, st->validate,
                  st->far_atlas, st->write};
    double total = 0;
    fprintf(out, "phase             seconds\n");
    for (int i = 0; i < 7; i++) {
        fprintf(out, "%-16s %8.3f\n", names[i], t[i]);
        total += t[i];
    }
    fprintf(out, "%-16s %8.3f\n", "total", total);
    if (st->up_to_date) {
        fprintf(out, "pack up to date: same input bytes, nothing rebuilt\n");
        fprintf(out, "combinations: %d (0 compiled)\n", st->combos);
        return;
    }
    fprintf(out, "combinations: %d (%d from cache, %d compiled)\n", st->combos,
            st->combos_cached, st->combos_compiled);
    fprintf(out, "combinations found in leaf cells: %d, pipelines built: %d "
            "(largest composite %d layers, largest leaf-cell overlap %d; "
            "%d coarse nodes left to the uber-shader)\n", st->combos_found, st->combos,
            st->largest, st->leaf_largest, st->uber_nodes);
    fprintf(out, "shaders: %d (%d from cache, %d compiled)\n", st->shaders,
            st->shaders_cached, st->shaders_compiled);
    fprintf(out, "spirv-val: %d modules validated, %d of known shape (float constants "
            "changed only)\n", st->shaders_compiled - st->shapes_known, st->shapes_known);
    fprintf(out, "lazy branches: %d in the fragment composites written\n",
            st->lazy_branches);
    fprintf(out, "distance classes: %d variants added\n", st->dclasses);
    fprintf(out, "pack files: %d written, %d kept from the old pack (same bytes)\n",
            st->files_written, st->files_kept);
}

/* The command line, parsed by the table below (args.h). */
typedef struct build_opts {
    splat_build_desc desc;
    bool             compute_spirv_default;   /* --compute-spirv: a no-op now */
    bool stats, json;
    const char *include[256];   /* -I DIR, in order */
    int ninclude;
} build_opts;

static bool parse_painted(const char *v, void *o, splat_arg_why *why)
{
    (void)why;
    return splat_painted_format_parse(v, &((build_opts *)o)->desc.painted);
}

static bool parse_far_bake(const char *v, void *o, splat_arg_why *why)
{
    (void)why;
    return splat_far_bake_parse(v, &((build_opts *)o)->desc.far_bake);
}

static bool parse_scene(const char *word, void *o_, splat_arg_why *why)
{
    build_opts *o = o_;
    if (o->desc.scene) {
        snprintf(why->text, sizeof why->text, "one scene at a time, found '%s' after '%s'",
                 word, o->desc.scene);
        return false;
    }
    o->desc.scene = word;
    return true;
}

/* The options: one row each; README.md's list is this table (splatc build
 * --help-markdown, checked by docs.options). */
#define F(field) offsetof(build_opts, field)
static const splat_arg options[] = {
    { "-o", SPLAT_ARG_STRING, "PACKDIR", "the shader pack folder to write (replaced only on "
      "success)", F(desc.out) },
    { "-j", SPLAT_ARG_INT, "N", "compile shaders on N threads (default 1; -jN too)",
      F(desc.jobs), .min = 1, .max = 256, .expects = "a thread count 1..256" },
    { "--stats", SPLAT_ARG_FLAG, NULL, "print the analysis report (cells, combinations, the "
      "largest one), per-phase times, cache hits, the lazy branches and distance classes "
      "added, and the painted masks' bytes next to their dense size", F(stats) },
    { "--cache", SPLAT_ARG_STRING, "DIR", "SPIR-V cache folder (default $SPLATC_CACHE, else "
      "$XDG_CACHE_HOME/splatc, else ~/.cache/splatc)", F(desc.cache_dir) },
    { "--no-cache", SPLAT_ARG_FLAG, NULL, "neither read nor write the cache",
      F(desc.no_cache) },
    { "--flat", SPLAT_ARG_FLAG, NULL, "also write each composite without dynamic branches",
      F(desc.flat) },
    { "--no-lazy", SPLAT_ARG_FLAG, NULL, "no lazy branches inside materials (a mix/select/mul "
      "side is skipped where its weight is 0; compiler/DESIGN.md 6.1)", F(desc.no_lazy) },
    { "--no-distance-classes", SPLAT_ARG_FLAG, NULL, "no distance class variants "
      "(compiler/distance.c)", F(desc.no_dclasses) },
    { "--max-combinations", SPLAT_ARG_INT, "P", "cover the leaf cells' combinations with at "
      "most P supersets, merging those that add the fewest layers (compiler/analysis.c; "
      "default 0: no merging)", F(desc.max_combos), .min = 0, .max = 65534,
      .expects = "a count 0..65534 (0: no merging)" },
    { "--glsl-compute", SPLAT_ARG_FLAG, NULL, "the compute variants, distance classes and "
      "undergrowth masks as GLSL only, compiled by the runtime on first use (default: SPIR-V "
      "made and validated here too)", F(desc.glsl_compute) },
    { "--compute-spirv", SPLAT_ARG_FLAG, NULL, "the default (SPIR-V of every stage made "
      "here); kept for old scripts", F(compute_spirv_default) },
    { "--painted", SPLAT_ARG_CUSTOM, "bc4|r8|dense", "painted mask storage: a sparse "
      "quad-tree with a BC4 atlas (bc4, the default) or an R8 atlas (r8), or dense rasters "
      "(painted.r8)", .parse = parse_painted, .expects = "bc4, r8 or dense" },
    { "--far-atlas", SPLAT_ARG_INT, "N", "also bake the far atlas: each terrain texel's "
      "composited albedo, normal and roughness, one atlas texel per N x N heightfield texels "
      "(default 1), BC-compressed (compiler/PACK.md \"Far atlas\")", F(desc.far_atlas),
      .optional = "1", .min = 1, .max = 64,
      .expects = "heightfield texels per atlas texel 1..64" },
    { "--far-bake", SPLAT_ARG_CUSTOM, "auto|cpu|gpu", "where to bake it: gpu (the Vulkan "
      "device; an error where there is none), cpu (the compiler's double-precision reference) "
      "or auto (the default: a GPU if there is one, a CPU's device (lavapipe) for atlases of "
      "10,000 texels a combination and more, else the CPU); $SPLAT_FAR_BAKE sets the default",
      .parse = parse_far_bake, .expects = "auto, cpu or gpu" },
    { "--preview", SPLAT_ARG_STRING, "M", "write material M's swatch pack instead: M alone on "
      "a built-in test hill under the scene's light (splatview --material renders it)",
      F(desc.preview) },
    { "-I", SPLAT_ARG_LIST, "DIR", "search DIR for imports (repeatable; then $SPLATC_PATH, "
      "'.', the project root, the installed nodes)", F(include), .count = F(ninclude),
      .capacity = 255 },
    { "--depfile", SPLAT_ARG_STRING, "FILE", "write a Make/Ninja depfile: "
      "PACKDIR/manifest.json and every file the pack was made from", F(desc.depfile) },
    { "--json", SPLAT_ARG_FLAG, NULL, "diagnostics as JSON Lines on stderr (for editors)",
      F(json) },
};
#undef F

static const splat_args_desc args = {
    .prog = "splatc build", .usage = "usage: splatc build SCENE.sg -o PACKDIR [options]\n",
    .args = options, .nargs = (int)(sizeof options / sizeof options[0]), .column = 24,
    .positional = parse_scene,
};

/* Options into o; 0, or the exit status (0 after --help: *done). */
static int parse_build_args(int argc, char **argv, build_opts *o, bool *done)
{
    memset(o, 0, sizeof *o);
    o->desc.jobs = 1;
    *done = false;
    const char *bake_env = getenv("SPLAT_FAR_BAKE");   /* --far-bake's default */
    if (bake_env && *bake_env && !splat_far_bake_parse(bake_env, &o->desc.far_bake)) {
        fprintf(stderr, "splatc build: SPLAT_FAR_BAKE expects auto, cpu or gpu, found '%s'\n",
                bake_env);
        return 2;
    }
    int rc = splat_args_parse(&args, argc, argv, 1, o);
    if (rc == SPLAT_ARGS_HELP) {
        *done = true;
        return 0;
    }
    if (rc)
        return rc;
    if (!o->desc.scene || !o->desc.out) {
        fprintf(stderr, "splatc build: %s\n",
                !o->desc.scene ? "no scene file given" : "no output folder (-o PACKDIR)");
        splat_args_help(&args, stderr);
        return 2;
    }
    if (o->desc.no_cache && o->desc.cache_dir) {
        fprintf(stderr, "splatc build: --cache and --no-cache exclude each other\n");
        return 2;
    }
    return 0;
}

int splat_cli_build(int argc, char **argv)
{
    build_opts o;
    bool done;
    int status = parse_build_args(argc, argv, &o, &done);
    if (status || done)
        return status;
    splat_build_desc desc = o.desc;
    char **search = splat_search_path(o.include, o.ninclude, desc.scene);
    desc.search_paths = (const char *const *)search;
    /* the -I folders, which the pack records (SPLATC_PATH is the
     * environment's, which splatview reads itself) */
    o.include[o.ninclude] = NULL;
    desc.pack_search = o.include;
    /* the report is held until the diagnostics are out, so a warning never
     * lands inside its tables (stdout and stderr share a terminal) */
    char *report = NULL;
    size_t report_len = 0;
    FILE *report_f = o.stats ? open_memstream(&report, &report_len) : NULL;
    if (o.stats && !report_f) {
        fprintf(stderr, "splatc build: out of memory\n");
        splat_search_path_free(search);
        return 1;
    }
    desc.report = report_f;
#ifdef SPLATC_DEVICE_BAKE
    rt_far_bake_host host = { .mode = desc.far_bake };
    desc.far_device = rt_far_bake_device;
    desc.far_device_user = &host;
#endif

    sg_diags d;
    sg_diags_init(&d);
    splat_build_stats st;
    bool ok = splat_build(&desc, &st, &d);
    if (o.json)
        sg_diags_print_json(&d, stderr);
    else
        sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    fflush(stderr);
    if (report_f) {
        fclose(report_f);
        if (ok)
            fwrite(report, 1, report_len, stdout);
        free(report);
    }
    if (ok && o.stats)
        print_stats(&st, stdout);
    splat_search_path_free(search);
    return ok ? 0 : 1;
}
