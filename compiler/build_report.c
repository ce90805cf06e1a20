/* build_report.c — the report of `splatc build --stats` (build.h): what
 * each composite costs against the über-shader (SPIR-V instructions,
 * textures, params), from the jobs just compiled or read back from an
 * up-to-date pack, and the painted masks as stored.
 */
#include "build.h"
#include "util.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "spv.h"
#include "zst.h"

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

void build_report_shaders(build *b, FILE *out)
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
    char why[256];   /* the pack is read as any input: no FIFO hangs here */
    size_t max = SPLAT_MAX_SPIRV_BYTES;
    FILE *f = splat_input_fopen(path, max, why, sizeof why);
    free(path);
    if (!f)
        return -1;
    uint8_t *data = NULL;
    size_t n = 0, cap = 0, got;
    do {
        if (n == cap) {
            cap = cap ? 2 * cap : 16384;
            data = xrealloc(data, cap);
        }
        got = fread(data + n, 1, cap - n, f);
        n += got;
    } while (got > 0);
    fclose(f);
    if (splat_zst_name(rel)) {   /* PACK.md "Compressed shaders" */
        size_t raw = 0;
        uint8_t *w = splat_zst_decompress(data, n, max, &raw, why, sizeof why);
        free(data);
        if (!w)
            return -1;
        data = w;
        n = raw;
    }
    int count = spirv_instructions((const uint32_t *)data, n / 4);
    free(data);
    return count;
}

/* The same report for a pack that is up to date, from its manifest and
 * SPIR-V files (nothing is composed or compiled). */
void build_report_shaders_from_pack(build *b, FILE *out)
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
void build_report_painted(build *b, FILE *out)
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
