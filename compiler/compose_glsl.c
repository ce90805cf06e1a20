/* compose_glsl.c — a composite's GLSL (splat_composite_glsl): a copy of
 * the composite with hoisted inputs as named leaves, scheduled
 * (compose_schedule.c), then emitted region by region: guards, lazy
 * branches, each layer's accumulation, the normalisation, the mask view
 * and the reference shader. */
#include "compose_internal.h"

#include <assert.h>
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "sg_internal.h"
#include "util.h"

#ifndef SPLATC_VERSION
#define SPLATC_VERSION "0"
#endif

/* ---- GLSL ----------------------------------------------------------------- */

/* The emitter writes leaves in place at every use, which would call
 * splat_normal() (four texture reads) once per use.  So GLSL is written
 * from a copy of the composite in which every terrain input marked `hoist`
 * in IR_INPUTS becomes a PARAM leaf named "in_<input>" and painted masks read as
 * "in_painted<L>"; those are declared by us, once, at the region the
 * scheduler places them in. */
typedef struct emit {
    const splat_layout    *L;
    const splat_composite *c;
    const ir              *src;      /* c->ir, or its differentiated copy    */
    const splat_layer     *src_layers; /* c->layers in src's ids             */
    ir                     ir;       /* the copy GLSL is written from       */
    splat_layer           *layers;   /* c->layers, in the copy's ids         */
    int                   *input_of; /* per param of the copy: input or -1  */
    uint32_t              *src_of;   /* per node of the copy: its id in src */
    glsl_emitter          *e;
    ir_buf                *out;
    sched                  s;
    char                   indent[256];
    const int             *ug_slot;  /* desc->ug_slot                        */
    bool                   normalised; /* the compositor has `blend`: sums
                                          s_wsum, divides before finishing */
    ir_buf                *decls;    /* long_chain: main's declarations of
                                        what its stretches compute, or NULL */
    int                    nstretch; /* long_chain: scopes its stretches pushed */
} emit;

static ir_ref map_ref(const uint32_t *map, ir_ref r)
{
    return (ir_ref){r.id ? map[r.id] : 0};
}

/* Build em->ir from the composite (same order, so operands stay first). */
static void emission_copy(emit *em)
{
    const ir *src = em->src;
    ir *dst = &em->ir;
    ir_init(dst);
    uint32_t *map = xcalloc(src->nnodes, sizeof *map);
    for (int i = 0; i < src->nparams; i++)
        ir_add_param(dst, &src->params[i]);
    for (int i = 0; i < src->ntextures; i++)
        ir_add_texture(dst, &src->textures[i]);
    for (int i = 0; i < src->npainted; i++)
        ir_add_painted(dst, src->painted[i].name);
    int input_param[IR_IN_COUNT];
    for (int i = 0; i < IR_IN_COUNT; i++)
        input_param[i] = -1;
    for (uint32_t id = 1; id < src->nnodes; id++) {
        ir_node n = src->nodes[id];
        for (int a = 0; a < n.nargs; a++)
            n.arg[a].id = map[n.arg[a].id];
        if (n.op == IR_OP_INPUT && ir_input_get((ir_input_kind)n.imm)->hoist) {
            if (input_param[n.imm] < 0) {
                const char *local = ir_input_get((ir_input_kind)n.imm)->local;
                ir_param p = {.name = (char *)local, .type = (ir_type)n.type};
                input_param[n.imm] = ir_add_param(dst, &p);
            }
            n.op = IR_OP_PARAM;
            n.imm = (uint32_t)input_param[n.imm];
        }
        map[id] = ir_node_add(dst, &n).id;
    }
    em->src_of = xcalloc(dst->nnodes, sizeof *em->src_of);
    for (uint32_t id = 1; id < src->nnodes; id++)
        em->src_of[map[id]] = id;
    em->input_of = xcalloc((size_t)dst->nparams, sizeof *em->input_of);
    for (int i = 0; i < dst->nparams; i++)
        em->input_of[i] = -1;
    for (int k = 0; k < IR_IN_COUNT; k++)
        if (input_param[k] >= 0)
            em->input_of[input_param[k]] = k;
    em->layers = xcalloc((size_t)em->c->nlayers, sizeof *em->layers);
    for (int j = 0; j < em->c->nlayers; j++) {
        const splat_layer *l = &em->src_layers[j];
        splat_layer *m = &em->layers[j];
        m->material = l->material;
        m->T = map_ref(map, l->T);
        m->mask = map_ref(map, l->mask);
        m->weight = map_ref(map, l->weight);
        m->T_next = map_ref(map, l->T_next);
        m->view_mask = map_ref(map, l->view_mask);
        for (int o = 0; o < SG_OUT_COUNT; o++)
            m->out[o] = map_ref(map, l->out[o]);
    }
    free(map);
}

static void emission_free(emit *em)
{
    ir_free(&em->ir);
    free(em->layers);
    free(em->input_of);
    free(em->src_of);
}

/* `type name = init;`, or in a long chain (em->decls) `name = init;`
 * with `type name;` among main's declarations, once. */
static void declare(emit *em, const char *type, const char *name, const char *init,
                    const char *ind)
{
    if (!em->decls) {
        ir_buf_printf(em->out, "%s%s %s = %s;\n", ind, type, name, init);
        return;
    }
    char line[160];
    snprintf(line, sizeof line, "    %s %s;\n", type, name);
    if (!em->decls->s || !strstr(em->decls->s, line))
        ir_buf_printf(em->decls, "%s", line);
    ir_buf_printf(em->out, "%s%s = %s;\n", ind, name, init);
}

/* Declare a leaf we name ourselves (an input or a painted mask). */
static void declare_leaf(emit *em, uint32_t id, const char *ind)
{
    const ir_node *n = &em->ir.nodes[id];
    if (n->op == IR_OP_PARAM && em->input_of[n->imm] >= 0) {
        const ir_input_info *in = ir_input_get((ir_input_kind)em->input_of[n->imm]);
        declare(em, ir_type_name((ir_type)n->type), in->local, in->glsl, ind);
    } else if (n->op == IR_OP_PAINTED) {
        char local[64], expr[64];
        compose_painted_local(em->L, em->ir.painted[n->imm].name, local, sizeof local, expr,
                              sizeof expr);
        declare(em, "float", local, expr, ind);
    }
}

static const char *indent_at(emit *em, int depth)
{
    int n = depth * 4;
    if (n > (int)sizeof em->indent - 1)
        n = (int)sizeof em->indent - 1;  /* deeper nesting: only less indent */
    memset(em->indent, ' ', (size_t)n);
    em->indent[n] = 0;
    return em->indent;
}

/* The value's GLSL, copied (the emitter's string may not outlive a call). */
static char *value(emit *em, ir_ref r, int depth)
{
    char ind[256];
    snprintf(ind, sizeof ind, "%s", indent_at(em, depth));
    return xstrdup(glsl_value(em->e, r, ind));
}

static void emit_placed(emit *em, int region, int depth);
static void close_block(emit *em, int depth);

/* The condition under which operand `a` of lazy node `id` counts. */
static char *lazy_condition(emit *em, uint32_t id, int a, int depth)
{
    const ir_node *n = &em->ir.nodes[id];
    ir_ref g = n->op == IR_OP_MIX ? n->arg[2] : n->op == IR_OP_SELECT ? n->arg[0]
                                                                      : n->arg[1 - a];
    if (ir_get(&em->ir, g)->op == IR_OP_SPLAT)   /* the scalar it repeats */
        g = ir_get(&em->ir, g)->arg[0];
    int w = ir_type_width(ir_typeof(&em->ir, g));
    const char *tn = ir_type_name(ir_typeof(&em->ir, g));
    char *x = value(em, g, depth);
    const char *op, *fn;
    const char *k = "0.0";
    if (n->op == IR_OP_MIX && a == 0) {
        op = "<", fn = "lessThan", k = "1.0";
    } else if (n->op == IR_OP_MIX) {
        op = ">", fn = "greaterThan";
    } else if (n->op == IR_OP_SELECT && a == 2) {
        op = "==", fn = "equal";
    } else {
        op = "!=", fn = "notEqual";
    }
    ir_buf b = {0};
    if (w == 1)
        ir_buf_printf(&b, "%s %s %s", x, op, k);
    else
        ir_buf_printf(&b, "any(%s(%s, %s(%s)))", fn, x, tn, k);
    free(x);
    return b.s;
}

/* Lazy node `id`'s kept sides: each side's region inside its branch, its
 * value left in `lz<id>_<a>` (0 where the branch is skipped), which the
 * node then reads. */
static void emit_lazy(emit *em, uint32_t id, int depth)
{
    const ir_node *n = &em->ir.nodes[id];
    for (int a = 0; a < n->nargs; a++) {
        int r = em->s.lazy[id][a];
        if (r < 0)
            continue;
        ir_ref x = n->arg[a];
        const char *tn = ir_type_name(ir_typeof(&em->ir, x));
        char name[48];
        snprintf(name, sizeof name, "lz%u_%d", id, a);
        char *cond = lazy_condition(em, id, a, depth);
        char zero[48];
        snprintf(zero, sizeof zero, "%s(0.0)", tn);
        declare(em, tn, name, zero, indent_at(em, depth));
        ir_buf_printf(em->out, "%sif (splat_quad_any(%s)) {\n", indent_at(em, depth), cond);
        free(cond);
        glsl_scope_push(em->e);
        emit_placed(em, r, depth + 1);
        char *v = value(em, x, depth + 1);
        ir_buf_printf(em->out, "%s%s = %s;\n", indent_at(em, depth + 1), name, v);
        free(v);
        close_block(em, depth);
        glsl_bind(em->e, x, name);
    }
}

/* Emit every value placed at `region`, operands first (id order). */
static void emit_placed(emit *em, int region, int depth)
{
    const ir *ir = &em->ir;
    char ind[256];
    snprintf(ind, sizeof ind, "%s", indent_at(em, depth));
    for (uint32_t i = 1; i < ir->nnodes; i++) {
        if (em->s.place[i] != region || ir->nodes[i].type == IR_T_TEX)
            continue;
        declare_leaf(em, i, ind);
        if (em->s.lazy)
            emit_lazy(em, i, depth);
        glsl_value(em->e, (ir_ref){i}, ind);
    }
}

/* Whether `r` is a constant, and its value. */
static bool is_const(const ir *ir, ir_ref r, double *v)
{
    const ir_node *n = ir_get(ir, r);
    if (n->op != IR_OP_CONST)
        return false;
    *v = n->val[0];
    return true;
}

/* Open a block guarded by `cond > 0.0`: a plain block if it is a positive
 * constant; false (nothing opened) if it is a constant <= 0.  `layer` >= 0:
 * the block is that layer's surface (abi.h splat_surface / splat_opaque,
 * which the sorted variant's first run skips); -1: a coverage guard. */
static bool open_guard(emit *em, ir_ref cond, int depth, int layer)
{
    double v;
    if (is_const(&em->ir, cond, &v)) {
        if (!(v > 0.0))
            return false;
        if (layer >= 0)
            ir_buf_printf(em->out, "%sif (splat_opaque(%du)) {\n", indent_at(em, depth), layer);
        else
            ir_buf_printf(em->out, "%s{\n", indent_at(em, depth));
    } else {
        char *x = value(em, cond, depth);
        /* quad-uniform, so implicit texture derivatives stay defined */
        if (layer >= 0)
            ir_buf_printf(em->out, "%sif (splat_surface(%du, %s > 0.0)) {\n",
                          indent_at(em, depth), layer, x);
        else
            ir_buf_printf(em->out, "%sif (splat_quad_any(%s > 0.0)) {\n",
                          indent_at(em, depth), x);
        free(x);
    }
    glsl_scope_push(em->e);
    return true;
}

/* The texture samples the current block itself takes, for the counting
 * variant (the hook is empty elsewhere: abi.h). */
static void count_samples(emit *em, int depth)
{
    int n = glsl_scope_count(em->e, IR_OP_SAMPLE) + glsl_scope_count(em->e, IR_OP_SAMPLE_GRAD);
    if (n > 0)
        ir_buf_printf(em->out, "%ssplat_count_samples(%du);\n", indent_at(em, depth), n);
}

static void close_block(emit *em, int depth)
{
    count_samples(em, depth + 1);
    glsl_scope_pop(em->e);
    ir_buf_printf(em->out, "%s}\n", indent_at(em, depth));
}

static const char *const acc_names[SG_OUT_COUNT] = {
    NULL, "s_albedo", "s_normal", "s_roughness", "s_height"};

static void emit_accumulate(emit *em, const splat_layer *l, int depth)
{
    double wv;
    bool unit = is_const(&em->ir, l->weight, &wv) && wv == 1.0;
    char *w = value(em, l->weight, depth);
    ir_buf_printf(em->out, "%ssplat_count_layer(%s);\n", indent_at(em, depth), w);
    if (em->normalised)
        ir_buf_printf(em->out, "%ss_wsum += %s;\n", indent_at(em, depth), w);
    if (em->ug_slot && em->ug_slot[l->material] >= 0)
        ir_buf_printf(em->out, "%ssplat_ug_weight(%d, %s);\n", indent_at(em, depth),
                      em->ug_slot[l->material], w);
    for (int o = 1; o < SG_OUT_COUNT; o++) {
        char *x = value(em, l->out[o], depth);
        if (unit)
            ir_buf_printf(em->out, "%s%s += %s;\n", indent_at(em, depth), acc_names[o], x);
        else
            ir_buf_printf(em->out, "%s%s += %s * %s;\n", indent_at(em, depth),
                          acc_names[o], w, x);
        free(x);
    }
    free(w);
}

/* A normalised compositor (its `blend` output, compiler/DESIGN.md §6.2):
 * the sums divided by the sum of the blends, the undergrowth weights too.
 * s_wsum > 0 wherever a layer was added (the bottom layer's alpha weight
 * is what the ones above left, and its blend a positive multiple of it);
 * the max only keeps the sorted variant's first run, which adds nothing,
 * away from 0 / 0. */
static void emit_normalise(emit *em)
{
    ir_buf_printf(em->out, "    float s_inv = 1.0 / max(s_wsum, 1e-30);\n"
                           "    s_albedo *= s_inv;\n"
                           "    s_roughness *= s_inv;\n"
                           "    s_height *= s_inv;\n");
    if (!em->ug_slot)
        return;
    for (int j = 0; j < em->c->nlayers; j++) {
        int slot = em->ug_slot[em->layers[j].material];
        if (slot >= 0)
            ir_buf_printf(em->out, "    splat_ug_weight(%d, splat_ug_w[%d] * s_inv);\n",
                          slot, slot);
    }
}

/* Chains of more than this many layers are emitted as a long_chain: a
 * guard per layer nests the code as deep as the chain is long, and
 * llvmpipe ignores every condition nested deeper than 80 (gallivm's
 * LP_MAX_TGSI_NESTING, Mesa 22.3): an über-shader drew the sky's colour
 * wherever its pixels needed a layer more than about 80 down the chain
 * (issue 29).  Breaks out of a do { } while (false) did not help there
 * (NaN pictures, the same wrong counters: the code after a break is still
 * nested in effect).  Shorter chains stay nested, their GLSL unchanged. */
#define SPLAT_NESTED_LAYERS_MAX 32

/* In a long_chain, guard what follows by `cond > 0.0`: the stretch ends
 * with s_go set from the guard, and the next one opens under s_go.  True
 * if what follows may run (a positive constant: the stretch goes on),
 * false if it never does (a constant <= 0: the chain ends). */
static bool stretch_guard(emit *em, ir_ref cond, int depth)
{
    double v;
    if (is_const(&em->ir, cond, &v))
        return v > 0.0;
    char *x = value(em, cond, depth);
    ir_buf_printf(em->out, "%ss_go = splat_quad_any(%s > 0.0);\n", indent_at(em, depth), x);
    free(x);
    count_samples(em, depth);
    ir_buf_printf(em->out, "%s}\n%sif (s_go) {\n", indent_at(em, depth - 1),
                  indent_at(em, depth - 1));
    /* the next stretch counts its samples from here; what this one
     * computed stays known, declared in main's scope (glsl_hoist) */
    glsl_scope_push(em->e);
    em->nstretch++;
    return true;
}

/* The layers of a long chain (SPLAT_NESTED_LAYERS_MAX), one stretch of
 * straight code per guard, each at the same depth:
 *     float v11; float in_slope; ...     (what the stretches compute)
 *     bool s_go = splat_quad_any(T0 > 0.0);
 *     if (s_go) {
 *         ... layer 0 ...
 *         s_go = splat_quad_any(T1 > 0.0);
 *     }
 *     if (s_go) {
 *         ... layer 1 ...
 * A stretch runs exactly where every guard up to its own passed, as when
 * nested; s_go is quad-uniform, as each guard was. */
static void emit_layer(emit *em, int j, bool flat, int depth);

static void long_chain(emit *em)
{
    double v;
    ir_ref t0 = em->layers[0].T;
    bool konst = is_const(&em->ir, t0, &v);
    if (konst && !(v > 0.0))
        return;
    ir_buf *out = em->out, chain = {0}, decls = {0};
    char *x = konst ? xstrdup("true") : value(em, t0, 1);
    ir_buf_printf(&chain, "    bool s_go = %s%s%s;\n    if (s_go) {\n",
                  konst ? "" : "splat_quad_any(", x, konst ? "" : " > 0.0)");
    free(x);
    em->out = &chain;   /* after the declarations, which it makes */
    em->decls = &decls;
    glsl_set_out(em->e, &chain);
    glsl_hoist(em->e, &decls);
    glsl_scope_push(em->e);
    em->nstretch = 1;
    emit_layer(em, 0, false, 2);
    count_samples(em, 2);
    ir_buf_printf(&chain, "    }\n");
    while (em->nstretch-- > 0)
        glsl_scope_pop(em->e);
    em->nstretch = 0;
    glsl_hoist(em->e, NULL);
    glsl_set_out(em->e, out);
    em->decls = NULL;
    em->out = out;
    if (decls.s)
        ir_buf_printf(out, "%s", decls.s);
    ir_buf_printf(out, "%s", chain.s);
    ir_buf_free(&decls);
    ir_buf_free(&chain);
}

/* Layer j: we are inside G_j's block (at `depth`). */
static void emit_layer(emit *em, int j, bool flat, int depth)
{
    const splat_layer *l = &em->layers[j];
    if (!flat)  /* flat: everything was placed at the root, emitted already */
        emit_placed(em, em->s.guard[j], depth);
    if (flat) {
        emit_accumulate(em, l, depth);
    } else if (ir_ref_eq(l->weight, l->T)) {  /* opaque: w = T, already > 0 */
        ir_buf_printf(em->out, "%sif (splat_opaque(%du)) {\n", indent_at(em, depth), j);
        glsl_scope_push(em->e);
        emit_placed(em, em->s.surface[j], depth + 1);
        emit_accumulate(em, l, depth + 1);
        close_block(em, depth);
    } else if (open_guard(em, l->weight, depth, j)) {
        emit_placed(em, em->s.surface[j], depth + 1);
        emit_accumulate(em, l, depth + 1);
        close_block(em, depth);
    }
    if (j + 1 >= em->c->nlayers)
        return;
    if (flat) {
        emit_layer(em, j + 1, flat, depth);
    } else if (em->decls) {
        if (stretch_guard(em, l->T_next, depth))
            emit_layer(em, j + 1, flat, depth);
    } else if (open_guard(em, l->T_next, depth, -1)) {
        emit_layer(em, j + 1, flat, depth + 1);
        close_block(em, depth);
    }
}

/* Emit what `roots` need at the current point (one straight-line block):
 * our own leaves declared first, then every value, operands first. */
static void emit_subtree(emit *em, const ir_ref *roots, int nroots, int depth)
{
    const ir *ir = &em->ir;
    uint8_t *reach = xcalloc(ir->nnodes, 1);
    for (int i = 0; i < nroots; i++)
        reach[roots[i].id] = 1;
    for (uint32_t id = ir->nnodes; id-- > 1;)
        if (reach[id])
            for (int a = 0; a < ir->nodes[id].nargs; a++)
                reach[ir->nodes[id].arg[a].id] = 1;
    char ind[256];
    snprintf(ind, sizeof ind, "%s", indent_at(em, depth));
    for (uint32_t id = 1; id < ir->nnodes; id++)
        if (reach[id] && ir->nodes[id].type != IR_T_TEX) {
            declare_leaf(em, id, ind);
            glsl_value(em->e, (ir_ref){id}, ind);
        }
    free(reach);
}

static void emit_mask_view(emit *em)
{
    ir_buf *o = em->out;
    ir_buf_printf(o, "    if (splat_view() == %uu) {\n", (unsigned)SPLAT_VIEW_MASK);
    ir_buf_printf(o, "        float mv = 0.0;\n");
    ir_buf_printf(o, "        switch (u_frame.view.y) {\n");
    for (int j = 0; j < em->c->nlayers; j++) {
        const splat_layer *l = &em->layers[j];
        ir_buf_printf(o, "        case %du: {  /* %s */\n", l->material,
                      em->L->materials[l->material]);
        glsl_scope_push(em->e);
        emit_subtree(em, &l->view_mask, 1, 3);
        char *x = value(em, l->view_mask, 3);
        ir_buf_printf(o, "            mv = %s;\n", x);
        free(x);
        glsl_scope_pop(em->e);
        ir_buf_printf(o, "        } break;\n");
    }
    ir_buf_printf(o, "        default: break;\n");
    ir_buf_printf(o, "        }\n");
    ir_buf_printf(o, "        o_color = vec4(vec3(mv), 1.0);\n");
    ir_buf_printf(o, "        return;\n");
    ir_buf_printf(o, "    }\n");
}

static const char *basename_of(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

static const char *const swizzle_of_type[IR_T_COUNT] = {
    [IR_T_FLOAT] = ".x", [IR_T_VEC2] = ".xy", [IR_T_VEC3] = ".xyz", [IR_T_VEC4] = ""};

static bool has_op(const ir *ir, int op)
{
    for (uint32_t id = 1; id < ir->nnodes; id++)
        if (ir->nodes[id].op == op)
            return true;
    return false;
}

/* Header comment and the set-1 declarations this shader uses. */
static void emit_header(emit *em, const splat_glsl_desc *desc)
{
    const splat_layout *L = em->L;
    const splat_composite *c = em->c;
    ir_buf *o = em->out;
    ir_buf_printf(o, "#version 450\n");
    ir_buf_printf(o, "/* %s — generated by splatc %s (ABI %d); do not edit.\n",
                  desc->title ? desc->title : "splatc shader", SPLATC_VERSION,
                  SPLAT_ABI_VERSION);
    ir_buf_printf(o, " * %s, top first:", c->reference ? "material" : "layers");
    for (int j = 0; j < c->nlayers; j++)
        ir_buf_printf(o, "%s %s (%d)", j ? "," : "",
                      L->materials[c->layers[j].material], c->layers[j].material);
    ir_buf_printf(o, "\n * set %d binding %d: splat_params, %d vec4 slot%s",
                  SPLAT_SET_MATERIAL, SPLAT_BIND_PARAMS, L->nparams > 0 ? L->nparams : 1,
                  L->nparams > 1 ? "s" : "");
    ir_buf_printf(o, "%s\n", c->nparams ? "; used here:" : "");
    for (int i = 0; i < c->nparams; i++)
        ir_buf_printf(o, " *   slot %d: %s %s\n", c->params[i],
                      ir_type_name(L->src->params[c->params[i]].type),
                      L->src->params[c->params[i]].name);
    for (int i = 0; i < c->ntextures; i++) {
        int x = c->textures[i];
        const ir_texture *t = &L->src->textures[L->textures[x]];
        ir_buf_printf(o, " * set %d binding %d: u_texa_%d layer %d = %s (%s, mip %s, %s%s)\n",
                      SPLAT_SET_MATERIAL, SPLAT_BIND_TEXTURE0 + L->tex_array[x],
                      L->tex_array[x], L->tex_layer[x], basename_of(t->file),
                      ir_filter_name(t->filter), ir_filter_name(t->mip), ir_wrap_name(t->wrap),
                      t->srgb ? ", sRGB" : "");
    }
    ir_buf_printf(o, " */\n");
    if (c->reference)
        ir_buf_printf(o, "#define SPLAT_MULTIPASS 1\n");
    if (desc->painted_sparse)
        ir_buf_printf(o, "#define SPLAT_PAINTED_SPARSE 1\n");
    if (desc->painted_sparse && desc->painted_places)
        ir_buf_printf(o, "%s", desc->painted_places);
    for (int i = 0; i < em->ir.npainted; i++)
        if (!strncmp(em->ir.painted[i].name, "vector.", 7)) {
            ir_buf_printf(o, "#define SPLAT_VECTORS 1\n");   /* binding 13 */
            break;
        }
    if (desc->compute)
        ir_buf_printf(o, "#define SPLAT_COMPUTE 1\n");
    else if (has_op(&em->ir, IR_OP_DINPUT))
        ir_buf_printf(o, "#define SPLAT_GRADIENTS 1\n");
    if (desc->ug_slot)
        ir_buf_printf(o, "#define SPLAT_UNDERGROWTH 1\n");
    ir_buf_printf(o, "%s", SPLAT_GLSL_PRELUDE);
    ir_buf_printf(o, "layout(set = %d, binding = %d, std140) uniform splat_params_block {\n"
                     "    vec4 slot[%d];\n} u_params;\n",
                  SPLAT_SET_MATERIAL, SPLAT_BIND_PARAMS, L->nparams > 0 ? L->nparams : 1);
    /* each array this composite reads, once (its textures' order) */
    for (int i = 0; i < c->ntextures; i++) {
        int a = L->tex_array[c->textures[i]], seen = 0;
        for (int j = 0; j < i; j++)
            seen |= L->tex_array[c->textures[j]] == a;
        if (!seen)
            ir_buf_printf(o, "layout(set = %d, binding = %d) uniform sampler2DArray u_texa_%d;\n",
                          SPLAT_SET_MATERIAL, SPLAT_BIND_TEXTURE0 + a, a);
    }
}

/* How the composite's param/texture/painted tables read in GLSL. */
typedef struct names {
    char      **param, **texture, **painted;
    int        *texture_layer;
    int         nparam, ntexture, npainted;
    char      **override;   /* precision.c's camera-relative forms       */
    const ir   *ir;
    glsl_names  g;
} names;

static void names_init(names *nm, const splat_layout *L, const ir *ir,
                       const int *input_of)
{
    nm->nparam = ir->nparams;
    nm->param = xcalloc((size_t)ir->nparams, sizeof *nm->param);
    int *param_of = xcalloc((size_t)ir->nparams + 1, sizeof *param_of);
    for (int i = 0; i < ir->nparams; i++) {
        param_of[i] = -1;
        if (input_of[i] >= 0) {
            nm->param[i] = xstrdup(ir_input_get((ir_input_kind)input_of[i])->local);
            continue;
        }
        int slot = 0;
        for (int p = 0; p < L->src->nparams; p++)
            if (strcmp(L->src->params[p].name, ir->params[i].name) == 0)
                slot = p;
        param_of[i] = slot;
        char buf[64];
        snprintf(buf, sizeof buf, "u_params.slot[%d]%s", slot,
                 swizzle_of_type[ir->params[i].type]);
        nm->param[i] = xstrdup(buf);
    }
    nm->ntexture = ir->ntextures;
    nm->texture = xcalloc((size_t)ir->ntextures, sizeof *nm->texture);
    nm->texture_layer = xcalloc((size_t)ir->ntextures + 1, sizeof *nm->texture_layer);
    for (int i = 0; i < ir->ntextures; i++) {
        int t = splat_layout_texture(L, &ir->textures[i]);
        char buf[32];
        snprintf(buf, sizeof buf, "u_texa_%d", L->tex_array[t]);
        nm->texture[i] = xstrdup(buf);
        nm->texture_layer[i] = L->tex_layer[t];
    }
    nm->npainted = ir->npainted;
    nm->painted = xcalloc((size_t)ir->npainted, sizeof *nm->painted);
    for (int i = 0; i < ir->npainted; i++) {
        char buf[64];
        compose_painted_local(L, ir->painted[i].name, buf, sizeof buf, NULL, 0);
        nm->painted[i] = xstrdup(buf);
    }
    nm->g.param = (const char *const *)nm->param;
    nm->g.texture = (const char *const *)nm->texture;
    nm->g.texture_layer = nm->texture_layer;
    nm->g.painted = (const char *const *)nm->painted;
    nm->ir = ir;
    nm->override = splat_sites_overrides(L, ir, param_of, input_of, &nm->g);
    if (!nm->override) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    nm->g.override = (const char *const *)nm->override;
    free(param_of);
}

static void names_free(names *nm)
{
    for (int i = 0; i < nm->nparam; i++)
        free(nm->param[i]);
    for (int i = 0; i < nm->ntexture; i++)
        free(nm->texture[i]);
    for (int i = 0; i < nm->npainted; i++)
        free(nm->painted[i]);
    free(nm->param);
    free(nm->texture);
    free(nm->texture_layer);
    free(nm->painted);
    splat_sites_overrides_free(nm->ir, nm->override);
}

static void emit_reference(emit *em)
{
    const splat_layer *l = &em->layers[0];
    emit_subtree(em, l->out, SG_OUT_COUNT, 1);
    char *x[SG_OUT_COUNT];
    for (int o = 1; o < SG_OUT_COUNT; o++)
        x[o] = value(em, l->out[o], 1);
    char *m = value(em, l->mask, 1);
    ir_buf_printf(em->out, "    splat_finish(%s, %s, %s, %s, %s);\n",
                  x[SG_OUT_ALBEDO], x[SG_OUT_NORMAL], x[SG_OUT_ROUGHNESS],
                  x[SG_OUT_HEIGHT], m);
    free(m);
    for (int o = 1; o < SG_OUT_COUNT; o++)
        free(x[o]);
}

/* The composite with explicit texture gradients (every stage: compute has
 * no quads, and the fragment stage takes the same gradients so the paths
 * agree): a copy of its ir through ir_differentiate, then one fold and dce
 * (the copy was optimised; one round folds the derivatives' zeros and
 * ones, and gives what the whole pipeline gives on the examples at 80 % of
 * its time); layers by root name. */
static void differentiated(const splat_composite *c, ir *dst, splat_layer *layers)
{
    ir_clone(dst, &c->ir);
    if (ir_pass_run(dst, "differentiate", NULL)) {
        ir_pass_run(dst, "fold", NULL);
        ir_pass_run(dst, "dce", NULL);
    }
    for (int j = 0; j < c->nlayers; j++)
        layers[j].material = c->layers[j].material;
    compose_layers_from_roots(dst, layers, c->nlayers);
}

/* Plateaus: whether a value can be exactly 0 (PLAT_0) or exactly 1
 * (PLAT_1) over an open set of pixels, not just at isolated points (a
 * noise's fade weight is 0 only on lattice lines: a branch on it would be
 * taken by every quad).  Clamping ops, steps, comparisons, selects, painted
 * masks, params and view.shading_lod (a constant of the pipeline) make
 * plateaus; products, sums and the like carry them; anything else (another
 * input, a texture, a sine) has none.  Always within the
 * interval bounds. */
static unsigned plateau_of(const ir *ir, uint32_t id, const ir_iv *iv, const uint8_t *p)
{
    const ir_node *n = &ir->nodes[id];
    unsigned a = n->nargs > 0 ? p[n->arg[0].id] : 0, b = n->nargs > 1 ? p[n->arg[1].id] : 0;
    unsigned c = n->nargs > 2 ? p[n->arg[2].id] : 0, r = 0;
    switch (n->op) {
    case IR_OP_CONST: case IR_OP_PARAM: case IR_OP_PAINTED:
    case IR_OP_SATURATE: case IR_OP_CLAMP: case IR_OP_SMOOTHSTEP: case IR_OP_STEP:
    case IR_OP_LESS:
        r = PLAT_0 | PLAT_1;
        break;
    case IR_OP_INPUT:   /* view.shading_lod is 0 or 1 on every pixel */
        r = n->imm == IR_IN_SHADING_LOD ? PLAT_0 | PLAT_1 : 0;
        break;
    case IR_OP_SPLAT: case IR_OP_SWIZZLE: case IR_OP_POW: case IR_OP_ABS: case IR_OP_NEG:
        r = a;
        break;
    case IR_OP_CONSTRUCT: case IR_OP_MIN: case IR_OP_MAX:
        for (int i = 0; i < n->nargs; i++)
            r |= p[n->arg[i].id];
        break;
    case IR_OP_SELECT:
        r = b | c;
        break;
    case IR_OP_MUL:
        r = ((a | b) & PLAT_0) | (a & b & PLAT_1);
        break;
    case IR_OP_DIV:
        r = a & PLAT_0;
        break;
    case IR_OP_ADD:   /* 0 + 0, 1 + 0 */
        r = (a & b & PLAT_0) | ((a & PLAT_1) && (b & PLAT_0)) * PLAT_1 |
            ((b & PLAT_1) && (a & PLAT_0)) * PLAT_1;
        break;
    case IR_OP_SUB:   /* 1 - 1, 0 - 0, 1 - 0 */
        r = ((a & b & PLAT_1) || (a & b & PLAT_0)) * PLAT_0 |
            ((a & PLAT_1) && (b & PLAT_0)) * PLAT_1;
        break;
    case IR_OP_MIX:   /* mix(a, b, 0) = a, mix(a, b, 1) = b */
        r = (a & b) | ((c & PLAT_0) ? a : 0) | ((c & PLAT_1) ? b : 0);
        break;
    default:
        break;
    }
    int w = ir_type_width((ir_type)n->type);
    if (!compose_can_be(iv, w, 0.0))
        r &= ~(unsigned)PLAT_0;
    if (!compose_can_be(iv, w, 1.0))
        r &= ~(unsigned)PLAT_1;
    return r;
}

/* Bounds of every node of the copy over the inputs' domains (params over
 * their [lo, hi]), from the source ir, which still has its inputs; and
 * each node's plateaus into *plat. */
static ir_iv (*lazy_bounds(const emit *em, uint8_t **plat))[4]
{
    ir_ienv env;
    memset(&env, 0, sizeof env);
    ir_ienv_domain(&env);
    const ir *s = em->src;
    ir_iv (*src)[4] = xcalloc(s->nnodes, sizeof *src);
    ir_interval_all(s, &env, src);
    uint8_t *sp = xcalloc(s->nnodes, 1);
    for (uint32_t id = 1; id < s->nnodes; id++)
        sp[id] = (uint8_t)plateau_of(s, id, src[id], sp);
    ir_iv (*iv)[4] = xcalloc(em->ir.nnodes, sizeof *iv);
    *plat = xcalloc(em->ir.nnodes, 1);
    for (uint32_t id = 1; id < em->ir.nnodes; id++) {
        memcpy(iv[id], src[em->src_of[id]], sizeof iv[id]);
        (*plat)[id] = sp[em->src_of[id]];
    }
    free(sp);
    free(src);
    return iv;
}

void splat_composite_glsl(const splat_layout *L, const splat_composite *c,
                          const splat_glsl_desc *desc, ir_buf *out)
{
    emit em = {.L = L, .c = c, .out = out, .src = &c->ir, .src_layers = c->layers,
               .ug_slot = desc->ug_slot,
               .normalised = !c->reference &&
                             splat_compositor_normalised(L->prog, L->compositor)};
    assert(!desc->ug_slot || desc->compute);
    ir dir;
    splat_layer *dlayers = NULL;
    assert(!(desc->compute && c->reference));
    /* Every stage samples with the compiler's gradients (splat_texture_grad), from
     * the same position derivatives (abi.c "Position derivatives"): the
     * forward, multi-pass and screen paths pick the same mip levels.  Not
     * for the lazy-side map (tests), which is indexed by c->ir's nodes. */
    if (!desc->lazy_sides) {
        dlayers = xcalloc((size_t)c->nlayers, sizeof *dlayers);
        differentiated(c, &dir, dlayers);
        em.src = &dir;
        em.src_layers = dlayers;
    }
    emission_copy(&em);
    names nm;
    names_init(&nm, L, &em.ir, em.input_of);
    emit_header(&em, desc);
    em.e = glsl_emitter_new(&em.ir, &nm.g, out);
    ir_buf_printf(out, "void main() {\n");
    if (c->reference) {
        emit_reference(&em);
    } else {
        if (!desc->no_mask_view)
            emit_mask_view(&em);
        for (int o = 1; o < SG_OUT_COUNT; o++)
            ir_buf_printf(out, "    %s %s = %s;\n",
                          o == SG_OUT_ALBEDO || o == SG_OUT_NORMAL ? "vec3" : "float",
                          acc_names[o],
                          o == SG_OUT_ALBEDO || o == SG_OUT_NORMAL ? "vec3(0.0)" : "0.0");
        if (em.normalised)
            ir_buf_printf(out, "    float s_wsum = 0.0;\n");
        uint8_t *plat = NULL;
        ir_iv (*bounds)[4] = NULL;
        if (!desc->flat && !desc->no_lazy) {
            bounds = lazy_bounds(&em, &plat);
            free(bounds);   /* the plateaus are within them */
        }
        compose_schedule(&em.s, &em.ir, em.layers, c->nlayers, desc->flat, plat);
        free(plat);
        if (desc->lazy_branches)
            *desc->lazy_branches += em.s.nlazy;
        if (desc->lazy_sides) {
            assert(!desc->compute);
            memset(desc->lazy_sides, 0, c->ir.nnodes);
            for (uint32_t id = 1; id < em.ir.nnodes; id++)
                for (int a = 0; a < 4; a++)
                    if (em.s.lazy[id][a] >= 0)
                        desc->lazy_sides[em.src_of[id]] |= (uint8_t)(1u << a);
        }
        emit_placed(&em, 0, 1);
        if (desc->flat) {
            emit_layer(&em, 0, true, 1);
        } else if (c->nlayers > SPLAT_NESTED_LAYERS_MAX) {
            long_chain(&em);
        } else if (open_guard(&em, em.layers[0].T, 1, -1)) {
            emit_layer(&em, 0, false, 2);
            close_block(&em, 1);
        }
        compose_sched_free(&em.s);
        count_samples(&em, 1);
        if (em.normalised)
            emit_normalise(&em);
        ir_buf_printf(out, "    splat_finish(s_albedo, normalize(s_normal), s_roughness, "
                           "s_height, 1.0);\n");
    }
    ir_buf_printf(out, "}\n");
    glsl_emitter_free(em.e);
    names_free(&nm);
    emission_free(&em);
    if (dlayers) {
        ir_free(&dir);
        free(dlayers);
    }
}
