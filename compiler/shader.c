/* shader.c — resource declarations and the single-material fragment
 * shader (see shader.h).  The ABI (bindings, prelude) is abi.h's. */
#include "shader.h"

#include "abi.h"

#include <assert.h>
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

static char *take(ir_buf *b)
{
    char *s = b->s;
    b->s = NULL;
    b->len = b->cap = 0;
    return s;
}

/* A GLSL identifier from a qualified name: other characters become '_',
 * runs of '_' collapse ("__" is reserved in GLSL), a leading digit or
 * "gl_" gets a "p_" prefix. */
static void mangle(const char *name, ir_buf *out)
{
    if (isdigit((unsigned char)name[0]) || strncmp(name, "gl_", 3) == 0 || !name[0])
        ir_buf_printf(out, "p_");
    char last = out->len ? out->s[out->len - 1] : 0;
    for (const char *p = name; *p; p++) {
        char c = isalnum((unsigned char)*p) ? *p : '_';
        if (c == '_' && last == '_')
            continue;
        ir_buf_printf(out, "%c", c);
        last = c;
    }
}

static const char *const swizzle_for_width[] = {"", ".x", ".xy", ".xyz", ""};

void glsl_declare_resources(const ir *ir, const int *painted_layer, ir_buf *out,
                            glsl_resources *res)
{
    memset(res, 0, sizeof *res);
    res->param = calloc((size_t)ir->nparams + 1, sizeof(char *));
    res->texture = calloc((size_t)ir->ntextures + 1, sizeof(char *));
    res->painted = calloc((size_t)ir->npainted + 1, sizeof(char *));
    if (!res->param || !res->texture || !res->painted) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    if (ir->nparams > 0) {
        ir_buf_printf(out, "layout(set = %d, binding = %d, std140) uniform splat_params {\n",
                      SPLAT_SET_MATERIAL, SPLAT_BIND_PARAMS);
        char **members = calloc((size_t)ir->nparams, sizeof(char *));
        for (int i = 0; i < ir->nparams; i++) {
            ir_buf m = {0};
            mangle(ir->params[i].name, &m);
            /* unique: a clash gets the slot index appended */
            for (int j = 0; j < i; j++)
                if (strcmp(members[j], m.s) == 0) {
                    ir_buf_printf(&m, "_%d", i);
                    break;
                }
            members[i] = take(&m);
            ir_buf_printf(out, "    vec4 %s;   // %s\n", members[i], ir->params[i].name);
            ir_buf e = {0};
            ir_buf_printf(&e, "u_params.%s%s", members[i],
                          swizzle_for_width[ir_type_width(ir->params[i].type)]);
            res->param[i] = take(&e);
        }
        ir_buf_printf(out, "} u_params;\n");
        for (int i = 0; i < ir->nparams; i++)
            free(members[i]);
        free(members);
    }
    for (int i = 0; i < ir->ntextures; i++) {
        ir_buf_printf(out, "layout(set = %d, binding = %d) uniform sampler2D t_tex%d;\n",
                      SPLAT_SET_MATERIAL, SPLAT_BIND_TEXTURE0 + i, i);
        ir_buf e = {0};
        ir_buf_printf(&e, "t_tex%d", i);
        res->texture[i] = take(&e);
    }
    for (int i = 0; i < ir->npainted; i++) {
        ir_buf e = {0};
        ir_buf_printf(&e, "splat_painted(%d)", painted_layer ? painted_layer[i] : i);
        res->painted[i] = take(&e);
    }
    res->names.param = (const char *const *)res->param;
    res->names.texture = (const char *const *)res->texture;
    res->names.painted = (const char *const *)res->painted;
}

void glsl_resources_free(glsl_resources *res)
{
    for (char **p = res->param; p && *p; p++)
        free(*p);
    for (char **p = res->texture; p && *p; p++)
        free(*p);
    for (char **p = res->painted; p && *p; p++)
        free(*p);
    free(res->param);
    free(res->texture);
    free(res->painted);
    memset(res, 0, sizeof *res);
}

/* Text safe inside a block comment. */
static void comment_text(ir_buf *out, const char *s)
{
    for (; *s; s++)
        ir_buf_printf(out, s[0] == '*' && s[1] == '/' ? "* " : "%c", *s);
}

void glsl_describe_resources(const ir *ir, const glsl_resources *res, ir_buf *out)
{
    ir_buf_printf(out, " * set 0: the terrain set of the ABI prelude (abi.h)\n");
    if (ir->nparams > 0)
        ir_buf_printf(out, " * set %d, binding %d: uniform block splat_params (std140, "
                      "one vec4 per param):\n", SPLAT_SET_MATERIAL, SPLAT_BIND_PARAMS);
    for (int i = 0; i < ir->nparams; i++) {
        const ir_param *p = &ir->params[i];
        ir_buf_printf(out, " *   offset %4d  %-24s %s ", 16 * i, res->param[i],
                      ir_type_name(p->type));
        comment_text(out, p->name);
        ir_buf_printf(out, " = %.9g", p->def[0]);
        for (int c = 1; c < ir_type_width(p->type); c++)
            ir_buf_printf(out, ", %.9g", p->def[c]);
        ir_buf_printf(out, "  range [%.9g, %.9g]\n", p->lo, p->hi);
    }
    for (int i = 0; i < ir->ntextures; i++) {
        const ir_texture *t = &ir->textures[i];
        ir_buf_printf(out, " * set %d, binding %d: sampler2D %s  \"", SPLAT_SET_MATERIAL,
                      SPLAT_BIND_TEXTURE0 + i, res->texture[i]);
        comment_text(out, t->file);
        ir_buf_printf(out, "\" (%s, mip %s, %s, %s)\n", ir_filter_name(t->filter), ir_filter_name(t->mip),
                      ir_wrap_name(t->wrap), t->srgb ? "sRGB" : "linear data");
    }
    for (int i = 0; i < ir->npainted; i++) {
        ir_buf_printf(out, " * painted mask \"");
        comment_text(out, ir->painted[i].name);
        ir_buf_printf(out, "\": %s\n", res->painted[i]);
    }
}

void glsl_material_shader(const ir *ir, const char *material, ir_buf *out)
{
    glsl_material_shader_stage(ir, material, false, out);
}

static void material_shader(const ir *ir, const char *material, bool compute,
                            ir_buf *out);

void glsl_material_shader_stage(const ir *ir, const char *material, bool compute,
                                ir_buf *out)
{
    if (!compute) {
        material_shader(ir, material, false, out);
        return;
    }
    /* no quads in compute: explicit gradients (ir_differentiate) */
    struct ir d;
    ir_clone(&d, ir);
    if (ir_pass_run(&d, "differentiate", NULL))
        ir_optimize(&d, NULL);
    material_shader(&d, material, true, out);
    ir_free(&d);
}

static void material_shader(const ir *ir, const char *material, bool compute,
                            ir_buf *out)
{
    /* The material outputs, in splat_finish's argument order after mask. */
    static const struct { const char *name; ir_type type; const char *def; } outs[] = {
        {"mask", IR_T_FLOAT, "1.0"},
        {"albedo", IR_T_VEC3, "vec3(0.5)"},
        {"normal", IR_T_VEC3, "splat_normal()"},
        {"roughness", IR_T_FLOAT, "0.8"},
        {"height", IR_T_FLOAT, "0.5"},
    };
    enum { NOUT = sizeof outs / sizeof outs[0] };

    ir_buf decl = {0};
    glsl_resources res;
    glsl_declare_resources(ir, NULL, &decl, &res);

    ir_buf_printf(out, "#version 450\n/* splatc: %s shader for material '",
                  compute ? "compute" : "fragment");
    comment_text(out, material);
    ir_buf_printf(out, "'.\n *\n * Resources:\n");
    glsl_describe_resources(ir, &res, out);
    ir_buf_printf(out, " *\n * main() computes the material's outputs (mask, albedo, normal, "
                  "roughness,\n * height) and hands them to splat_finish().\n */\n");
    if (compute)
        ir_buf_printf(out, "#define SPLAT_COMPUTE 1\n");
    ir_buf_printf(out, "%s", SPLAT_GLSL_PRELUDE);
    ir_buf_printf(out, "%s", decl.s ? decl.s : "");
    ir_buf_printf(out, "\nvoid main() {\n");

    glsl_emitter *e = glsl_emitter_new(ir, &res.names, out);
    char *expr[NOUT];
    for (int i = 0; i < NOUT; i++) {
        ir_buf root = {0};
        ir_buf_printf(&root, "%s.%s", material, outs[i].name);
        ir_ref r = ir_find_root(ir, root.s);
        ir_buf_free(&root);
        if (ir_ref_ok(r)) {
            assert(ir_typeof(ir, r) == outs[i].type);
            expr[i] = strdup(glsl_value(e, r, "    "));
        } else {
            expr[i] = strdup(outs[i].def);
        }
    }
    ir_buf_printf(out, "    splat_finish(%s, %s, %s, %s, %s);\n}\n",
                  expr[1], expr[2], expr[3], expr[4], expr[0]);
    for (int i = 0; i < NOUT; i++)
        free(expr[i]);
    glsl_emitter_free(e);
    glsl_resources_free(&res);
    ir_buf_free(&decl);
}
