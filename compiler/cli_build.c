/* cli_build.c — `splatc build SCENE.sg -o PACKDIR [-j N] [--stats]
 * [--cache DIR | --no-cache] [--flat] [--no-lazy] [--glsl-compute] [--no-distance-classes]
 * [--max-combinations P]
 * [--painted bc4|r8|dense] [-I DIR]... [--depfile FILE] [--preview MATERIAL] [--far-atlas[=N]]
 * [--far-bake auto|cpu|gpu] [--json]`:
 * the command-line face
 * of splat_build (build.c).  Exit status 0 on success, 1 on input errors,
 * 2 on usage errors. */
#include "cli.h"
#include "scene.h"
#include "util.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifdef SPLATC_DEVICE_BAKE   /* the runtime is built: it bakes on a device */
#include "splatrt.h"
#endif

static const char usage[] =
    "usage: splatc build SCENE.sg -o PACKDIR [options]\n"
    "  -o PACKDIR     the shader pack folder to write (replaced only on success)\n"
    "  -j N           compile shaders on N threads (default 1)\n"
    "  --stats        print the analysis report, per-phase times, cache hits\n"
    "                 and the painted masks' bytes next to their dense size\n"
    "  --cache DIR    SPIR-V cache folder (default $SPLATC_CACHE, else\n"
    "                 $XDG_CACHE_HOME/splatc, else ~/.cache/splatc)\n"
    "  --no-cache     neither read nor write the cache\n"
    "  --flat         also write each composite without dynamic branches\n"
    "  --no-lazy      no lazy branches inside materials (a mix/select/mul side\n"
    "                 is skipped where its weight is 0; compiler/DESIGN.md 6.1)\n"
    "  --glsl-compute the compute variants, distance classes and undergrowth\n"
    "                 masks as GLSL only, compiled by the runtime on first use\n"
    "                 (default: SPIR-V made and validated here too; the old\n"
    "                 --compute-spirv is that default)\n"
    "  --no-distance-classes  no distance class variants (compiler/distance.c)\n"
    "  --max-combinations P  cover the leaf cells' combinations with at most P\n"
    "                 supersets, merging those that add the fewest layers\n"
    "                 (compiler/analysis.c; default 0: no merging)\n"
    "  --painted F    painted mask storage: bc4 (default: sparse quad-tree,\n"
    "                 BC4 atlas), r8 (sparse, R8 atlas) or dense (painted.r8)\n"
    "  -I DIR         search DIR for imports (repeatable; then $SPLATC_PATH,\n"
    "                 '.', the project root, the installed nodes)\n"
    "  --depfile FILE write a Make/Ninja depfile: PACKDIR/manifest.json and\n"
    "                 every file the pack was made from\n"
    "  --preview M    write material M's swatch pack instead: M alone on a\n"
    "                 built-in test hill under the scene's light (splatview\n"
    "                 --material renders it)\n"
    "  --far-atlas[=N]  also bake the far atlas: each terrain texel's composited\n"
    "                 albedo, normal and roughness, one atlas texel per N x N\n"
    "                 heightfield texels (default 1), BC-compressed (far.atlas)\n"
    "  --far-bake W   where to bake it: gpu (the Vulkan device; an error where\n"
    "                 there is none), cpu (the compiler's double reference) or\n"
    "                 auto (default: a GPU if there is one, a CPU's device\n"
    "                 (lavapipe) for atlases of 10,000 texels a combination\n"
    "                 and more, else the CPU;\n"
    "                 $SPLAT_FAR_BAKE sets the default)\n"
    "  --json         diagnostics as JSON Lines on stderr (for editors)\n";

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
}

int splat_cli_build(int argc, char **argv)
{
    splat_build_desc desc = {.jobs = 1};
    const char *bake_env = getenv("SPLAT_FAR_BAKE");   /* --far-bake's default */
    if (bake_env && *bake_env && !splat_far_bake_parse(bake_env, &desc.far_bake)) {
        fprintf(stderr, "splatc build: SPLAT_FAR_BAKE expects auto, cpu or gpu, found '%s'\n",
                bake_env);
        return 2;
    }
    bool stats = false, json = false;
    const char **include = xcalloc((size_t)argc + 1, sizeof *include);
    int ninclude = 0;
    char **search = NULL;
    int status = 2;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            fputs(usage, stdout);
            status = 0;
            goto done;
        } else if (strcmp(a, "-o") == 0 && next) {
            desc.out = next;
            i++;
        } else if (strncmp(a, "-j", 2) == 0 && (a[2] || next)) {
            /* -j N or -jN, as make takes it */
            const char *v = a[2] ? a + 2 : next;
            char *end;
            long n = strtol(v, &end, 10);
            if (*end || n < 1 || n > 256) {
                fprintf(stderr, "splatc build: -j expects a thread count 1..256, found '%s'\n",
                        v);
                goto done;
            }
            desc.jobs = (int)n;
            if (!a[2])
                i++;
        } else if (strcmp(a, "--stats") == 0) {
            stats = true;
        } else if (strcmp(a, "--cache") == 0 && next) {
            desc.cache_dir = next;
            i++;
        } else if (strcmp(a, "--no-cache") == 0) {
            desc.no_cache = true;
        } else if (strcmp(a, "--flat") == 0) {
            desc.flat = true;
        } else if (strcmp(a, "--no-lazy") == 0) {
            desc.no_lazy = true;
        } else if (strcmp(a, "--compute-spirv") == 0) {
            desc.glsl_compute = false;   /* the default since issue 29 */
        } else if (strcmp(a, "--glsl-compute") == 0) {
            desc.glsl_compute = true;
        } else if (strcmp(a, "--far-atlas") == 0 || strncmp(a, "--far-atlas=", 12) == 0) {
            char *end;
            long n = a[11] ? strtol(a + 12, &end, 10) : 1;
            if (a[11] && (*end || n < 1 || n > 64)) {
                fprintf(stderr, "splatc build: --far-atlas=N expects heightfield texels per "
                                "atlas texel 1..64, found '%s'\n", a + 12);
                goto done;
            }
            desc.far_atlas = (int)n;
        } else if (strcmp(a, "--far-bake") == 0 && next) {
            if (!splat_far_bake_parse(next, &desc.far_bake)) {
                fprintf(stderr, "splatc build: --far-bake expects auto, cpu or gpu, found '%s'\n",
                        next);
                goto done;
            }
            i++;
        } else if (strcmp(a, "--max-combinations") == 0 && next) {
            char *end;
            long n = strtol(next, &end, 10);
            if (*end || !*next || n < 0 || n > 65534) {
                fprintf(stderr, "splatc build: --max-combinations expects a count 0..65534 "
                                "(0: no merging), found '%s'\n", next);
                goto done;
            }
            desc.max_combos = (int)n;
            i++;
        } else if (strcmp(a, "--no-distance-classes") == 0) {
            desc.no_dclasses = true;
        } else if (strcmp(a, "--painted") == 0 && next) {
            if (!splat_painted_format_parse(next, &desc.painted)) {
                fprintf(stderr, "splatc build: --painted expects bc4, r8 or dense, found '%s'\n",
                        next);
                goto done;
            }
            i++;
        } else if (strcmp(a, "-I") == 0 && next) {
            include[ninclude++] = next;
            i++;
        } else if (strcmp(a, "--depfile") == 0 && next) {
            desc.depfile = next;
            i++;
        } else if (strcmp(a, "--preview") == 0 && next) {
            desc.preview = next;
            i++;
        } else if (strcmp(a, "--json") == 0) {
            json = true;
        } else if (a[0] == '-') {
            fprintf(stderr, "splatc build: unknown or incomplete option '%s'\n%s", a, usage);
            goto done;
        } else if (!desc.scene) {
            desc.scene = a;
        } else {
            fprintf(stderr, "splatc build: one scene at a time, found '%s' after '%s'\n",
                    a, desc.scene);
            goto done;
        }
    }
    if (!desc.scene || !desc.out) {
        fprintf(stderr, "splatc build: %s\n%s",
                !desc.scene ? "no scene file given" : "no output folder (-o PACKDIR)", usage);
        goto done;
    }
    if (desc.no_cache && desc.cache_dir) {
        fprintf(stderr, "splatc build: --cache and --no-cache exclude each other\n");
        goto done;
    }
    search = splat_search_path(include, ninclude, desc.scene);
    desc.search_paths = (const char *const *)search;
    /* the -I folders, which the pack records (SPLATC_PATH is the
     * environment's, which splatview reads itself) */
    include[ninclude] = NULL;
    desc.pack_search = include;
    /* the report is held until the diagnostics are out, so a warning never
     * lands inside its tables (stdout and stderr share a terminal) */
    char *report = NULL;
    size_t report_len = 0;
    FILE *report_f = stats ? open_memstream(&report, &report_len) : NULL;
    if (stats && !report_f) {
        fprintf(stderr, "splatc build: out of memory\n");
        status = 1;
        goto done;
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
    if (json)
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
    if (ok && stats)
        print_stats(&st, stdout);
    status = ok ? 0 : 1;
done:
    splat_search_path_free(search);
    free(include);
    return status;
}
