/* harness_ir.c — evaluate IR roots on the device (harness.h).
 *
 * The IR goes through the compiler's own GLSL emitter (glsl.c), inside a
 * compute shader whose prelude defines the inputs the ABI prelude defines
 * for fragment shaders, read from a per-point record instead of the
 * heightfield:
 *
 *   rec[0]                 height, slope, view distance, destruction
 *   rec[1]                 normal.xyz, view direction.x
 *   rec[2]                 position.xyz, view direction.y
 *   rec[3]                 uv.xy, view direction.z, cavity
 *   rec[4 + i]             param i (its first ir_type_width components)
 *   rec[4 + P + k / 4][k % 4]  painted mask k        (P = number of params)
 *
 * One vec4 per root per point comes back. */
#include "harness.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "spv.h"

static void set_err(char **err, const char *msg, const char *detail)
{
    if (!err || *err)
        return;
    size_t n = strlen(msg) + (detail ? strlen(detail) : 0) + 3;
    if ((*err = malloc(n)))
        snprintf(*err, n, "%s%s%s", msg, detail ? ": " : "", detail ? detail : "");
}

static int record_vec4s(const ir *ir)
{
    return 4 + ir->nparams + (ir->npainted + 3) / 4;
}

static const char *swizzle_for(ir_type t)
{
    switch (ir_type_width(t)) {
    case 1:  return ".x";
    case 2:  return ".xy";
    case 3:  return ".xyz";
    default: return "";
    }
}

/* The shader's inputs, as the ABI prelude names them. */
static const char INPUTS[] =
    "float splat_height() { return h_in.rec[h_base].x; }\n"
    "float splat_slope() { return h_in.rec[h_base].y; }\n"
    "float splat_view_distance() { return h_in.rec[h_base].z; }\n"
    "float splat_destruction() { return h_in.rec[h_base].w; }\n"
    "vec3 splat_normal() { return h_in.rec[h_base + 1u].xyz; }\n"
    "vec3 splat_position() { return h_in.rec[h_base + 2u].xyz; }\n"
    "vec2 splat_uv() { return h_in.rec[h_base + 3u].xy; }\n"
    "float splat_cavity() { return h_in.rec[h_base + 3u].w; }\n"
    "float splat_shading_lod() { return 0.0; }\n"   /* the full shading */
    "vec3 splat_view_direction() {\n"
    "    return vec3(h_in.rec[h_base + 1u].w, h_in.rec[h_base + 2u].w, h_in.rec[h_base + 3u].z);\n"
    "}\n";

char *harness_ir_shader(const harness_ir_desc *d, char **err)
{
    const ir *ir = d->ir;
    for (int r = 0; r < d->nroots; r++) {
        int w = ir_type_width(ir_typeof(ir, d->roots[r]));
        if (w < 1 || w > 4) {
            set_err(err, "harness_ir_shader: a root is not a float or vector",
                    ir_type_name(ir_typeof(ir, d->roots[r])));
            return NULL;
        }
    }

    /* How the emitter names params, textures and painted masks. */
    int np = ir->nparams, nt = ir->ntextures, nm = ir->npainted;
    char **pnames = calloc((size_t)np + 1, sizeof *pnames);
    char **tnames = calloc((size_t)nt + 1, sizeof *tnames);
    char **mnames = calloc((size_t)nm + 1, sizeof *mnames);
    char *result = NULL;
    ir_buf b = {0};
    if (!pnames || !tnames || !mnames) {
        set_err(err, "out of memory", NULL);
        goto done;
    }
    for (int i = 0; i < np; i++) {
        ir_buf s = {0};
        ir_buf_printf(&s, "h_in.rec[h_base + %du]%s", 4 + i,
                      swizzle_for(ir->params[i].type));
        pnames[i] = s.s;
    }
    for (int i = 0; i < nt; i++) {
        ir_buf s = {0};
        ir_buf_printf(&s, "h_tex%d", i);
        tnames[i] = s.s;
    }
    for (int k = 0; k < nm; k++) {
        ir_buf s = {0};
        ir_buf_printf(&s, "h_in.rec[h_base + %du].%c", 4 + np + k / 4, "xyzw"[k % 4]);
        mnames[k] = s.s;
    }

    ir_buf_printf(&b,
        "#version 450\n"
        "/* splat harness: IR roots evaluated per point (tests/harness) */\n"
        "layout(local_size_x = %d) in;\n"
        "layout(std430, set = 0, binding = 0) readonly buffer harness_in { vec4 rec[]; } h_in;\n"
        "layout(std430, set = 0, binding = 1) writeonly buffer harness_out { vec4 v[]; } h_out;\n",
        HARNESS_LOCAL_SIZE);
    for (int i = 0; i < nt; i++)
        ir_buf_printf(&b, "layout(set = 0, binding = %d) uniform sampler2D h_tex%d;\n",
                      2 + i, i);
    ir_buf_printf(&b, "const uint H_REC = %du;\nconst uint H_ROOTS = %du;\nuint h_base;\n%s",
                  record_vec4s(ir), d->nroots, INPUTS);
    ir_buf_printf(&b,
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        "    if (i >= uint(h_in.rec.length()) / H_REC) return;\n"
        "    h_base = i * H_REC;\n");

    glsl_names names = {
        .param = (const char *const *)pnames,
        .texture = (const char *const *)tnames,
        .painted = (const char *const *)mnames,
    };
    glsl_emitter *e = glsl_emitter_new(ir, &names, &b);
    if (!e) {
        set_err(err, "harness_ir_shader: glsl_emitter_new failed", NULL);
        goto done;
    }
    static const char *const pad[] = { "", ", 0.0, 0.0, 0.0", ", 0.0, 0.0", ", 0.0", "" };
    for (int r = 0; r < d->nroots; r++) {
        ir_type t = ir_typeof(ir, d->roots[r]);
        const char *v = glsl_value(e, d->roots[r], "    ");
        ir_buf_printf(&b, "    h_out.v[i * H_ROOTS + %du] = vec4(%s%s);\n", r, v,
                      pad[ir_type_width(t)]);
    }
    glsl_emitter_free(e);
    ir_buf_printf(&b, "}\n");
    result = b.s;
    b.s = NULL;

done:
    for (int i = 0; pnames && i < np; i++)
        free(pnames[i]);
    for (int i = 0; tnames && i < nt; i++)
        free(tnames[i]);
    for (int i = 0; mnames && i < nm; i++)
        free(mnames[i]);
    free(pnames);
    free(tnames);
    free(mnames);
    ir_buf_free(&b);
    return result;
}

/* Pack the points into records of fp32 (layout above). */
static float *pack_points(const harness_ir_desc *d, size_t *bytes)
{
    const ir *ir = d->ir;
    const int R = record_vec4s(ir);
    float *rec = calloc((size_t)d->npoints * (size_t)R * 4, sizeof *rec);
    if (!rec)
        return NULL;
    for (int p = 0; p < d->npoints; p++) {
        const ir_env *env = &d->points[p];
        float *r = rec + (size_t)p * (size_t)R * 4;
        r[0] = (float)env->height;
        r[1] = (float)env->slope;
        r[2] = (float)env->view_distance;
        r[3] = (float)env->destruction;
        for (int c = 0; c < 3; c++) {
            r[4 + c] = (float)env->normal[c];
            r[8 + c] = (float)env->position[c];
        }
        r[12] = (float)env->uv[0];
        r[13] = (float)env->uv[1];
        /* view direction as ir_eval reads it: unset (0, 0, 0) is straight up */
        const double *vd = env->view_direction;
        bool unset = vd[0] == 0.0 && vd[1] == 0.0 && vd[2] == 0.0;
        r[7] = (float)vd[0];
        r[11] = (float)(unset ? 1.0 : vd[1]);
        r[14] = (float)vd[2];
        r[15] = (float)env->cavity;
        for (int i = 0; i < ir->nparams; i++)
            for (int c = 0; c < 4; c++)
                r[(4 + i) * 4 + c] = (float)(env->params ? env->params[4 * i + c]
                                                         : ir->params[i].def[c]);
        for (int k = 0; k < ir->npainted; k++)
            r[(4 + ir->nparams) * 4 + k] = (float)(env->painted ? env->painted[k] : 0.0);
    }
    *bytes = (size_t)d->npoints * (size_t)R * 4 * sizeof(float);
    return rec;
}

bool harness_eval_ir(harness *h, const harness_ir_desc *d, float *out,
                     char **glsl, char **err)
{
    if (err)
        *err = NULL;
    if (glsl)
        *glsl = NULL;
    if (d->npoints <= 0 || d->nroots <= 0) {
        set_err(err, "harness_eval_ir: no points or no roots", NULL);
        return false;
    }
    bool ok = false;
    uint32_t *spv = NULL;
    size_t nwords = 0;
    float *input = NULL;
    harness_image *images = NULL;
    static const float grey[4] = { 0.5f, 0.5f, 0.5f, 1.0f };

    char *src = harness_ir_shader(d, err);
    if (!src)
        return false;
    char *log = NULL;
    if (!spv_compile(src, SPV_STAGE_COMPUTE, "harness", &spv, &nwords, &log)) {
        set_err(err, "harness_eval_ir", log);
        free(log);
        goto done;
    }
    free(log);

    size_t in_bytes = 0;
    input = pack_points(d, &in_bytes);
    int nt = d->ir->ntextures;
    images = calloc((size_t)nt + 1, sizeof *images);
    if (!input || !images) {
        set_err(err, "out of memory", NULL);
        goto done;
    }
    for (int i = 0; i < nt; i++)
        images[i] = d->images ? d->images[i]
                              : (harness_image){ 1, 1, grey, d->ir->textures[i].filter,
                                                 d->ir->textures[i].wrap };
    harness_dispatch disp = {
        .spv = spv,
        .nwords = nwords,
        .input = input,
        .input_bytes = in_bytes,
        .output = out,
        .output_bytes = (size_t)d->npoints * (size_t)d->nroots * 4 * sizeof(float),
        .groups = (uint32_t)((d->npoints + HARNESS_LOCAL_SIZE - 1) / HARNESS_LOCAL_SIZE),
        .images = images,
        .nimages = nt,
    };
    ok = harness_run(h, &disp, err);

done:
    if (glsl)
        *glsl = src;
    else
        free(src);
    free(spv);
    free(input);
    free(images);
    return ok;
}
