/* resolve_names.c — names in a scope: what each value's path names (a
 * local input, param or node and its output, a global texture, a terrain
 * input), swizzles, and "did you mean" for what names nothing (the
 * closest node type, port or name by edit distance). */
#include "resolve.h"
#include "util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* An unknown global name (node type, texture, material, compositor) is
 * most likely one of a failed import's: leave it out, the import's error
 * says what to do.  The scope is then not ok, though no error is added. */
bool rs_after_failed_import(checker *c)
{
    if (c->p->failed_imports == 0)
        return false;
    c->suppressed++;
    return true;
}


void rs_duplicate(checker *c, sg_loc loc, const char *what, const char *name,
                      sg_loc first)
{
    sg_error(c->d, loc, SG_E_DUPLICATE, what, name, first.file, first.line, first.col);
}

static bool swizzle_ok(const char *sw, int *len)
{
    int n = (int)strlen(sw);
    if (n < 1 || n > 4)
        return false;
    bool xyzw = strchr("xyzw", sw[0]) != NULL;
    for (int i = 0; i < n; i++)
        if (!strchr(xyzw ? "xyzw" : "rgba", sw[i]))
            return false;
    *len = n;
    return true;
}

static int swizzle_comp(char ch)
{
    const char *p = strchr("xyzw", ch);
    return p ? (int)(p - "xyzw") : (int)(strchr("rgba", ch) - "rgba");
}

/* Type of `base` with v->swizzle applied; reports a bad swizzle. */
ir_type rs_apply_swizzle(checker *c, sg_value *v, ir_type base)
{
    if (!v->swizzle || base == IR_T_ERROR)
        return base;
    int n = 0;
    swizzle_ok(v->swizzle, &n);
    int w = ir_type_width(base);
    for (int i = 0; i < n; i++)
        if (w == 0 || swizzle_comp(v->swizzle[i]) >= w) {
            char msg[128];
            snprintf(msg, sizeof msg, "swizzle '.%s' reads past the end of a %s",
                     v->swizzle, ir_type_name(base));
            sg_error(c->d, v->loc, SG_E_BAD_SWIZZLE, msg);
            return IR_T_ERROR;
        }
    return ir_type_vec(n);
}

static const char *path_text(const sg_value *v, char *buf, size_t n)
{
    buf[0] = 0;
    size_t o = 0;
    for (int i = 0; i < v->nparts && o < n; i++)
        o += (size_t)snprintf(buf + o, n - o, "%s%s", i ? "." : "", v->parts[i]);
    return buf;
}

/* ---- did you mean ---------------------------------------------------------- */

/* The node type `word` may have meant: terrain and view inputs, painted,
 * the built-in ops, the program's shaders. */
const char *rs_near_node_type(checker *c, const char *word)
{
    sg_suggest sg;
    sg_suggest_init(&sg, word);
    for (int i = 0; i < IR_IN_COUNT; i++)
        sg_suggest_offer(&sg, ir_input_get((ir_input_kind)i)->name);
    sg_suggest_offer(&sg, "painted");
    for (int i = 0; i < IR_OP_COUNT; i++)
        sg_suggest_offer(&sg, ir_opinfo_get((ir_op)i)->name);
    for (int i = 0; i < c->p->nshaders; i++)
        if (!c->p->shaders[i]->is_material)
            sg_suggest_offer(&sg, c->p->shaders[i]->name);
    return sg_suggest_best(&sg);
}

const char *rs_near_port(const sg_port *ports, int n, const char *word)
{
    sg_suggest sg;
    sg_suggest_init(&sg, word);
    for (int i = 0; i < n; i++)
        sg_suggest_offer(&sg, ports[i].name);
    return sg_suggest_best(&sg);
}

/* A name in scope that `word` may have meant: the shader's inputs,
 * params and nodes, the program's textures, the terrain and view inputs
 * (for "terrain.positon", only those). */
static const char *near_name(checker *c, const char *word, bool allow_locals)
{
    sg_suggest sg;
    sg_suggest_init(&sg, word);
    bool dotted = strchr(word, '.') != NULL;
    if (!dotted) {
        const sg_shader *s = c->s;
        for (int i = 0; s && i < s->nins; i++)
            sg_suggest_offer(&sg, s->ins[i].name);
        for (int i = 0; s && i < s->nparams; i++)
            sg_suggest_offer(&sg, s->params[i].name);
        for (int i = 0; s && allow_locals && i < s->nnodes; i++)
            sg_suggest_offer(&sg, s->nodes[i].name);
        for (int i = 0; i < c->p->ntextures; i++)
            sg_suggest_offer(&sg, c->p->textures[i]->name);
    }
    for (int i = 0; i < IR_IN_COUNT; i++)
        sg_suggest_offer(&sg, ir_input_get((ir_input_kind)i)->name);
    return sg_suggest_best(&sg);
}

/* "take the first N components with '.rgb'" for a value one swizzle away
 * from the type wanted (a wider vector into a narrower port). */
void rs_hint_swizzle(checker *c, const sg_value *v, ir_type want)
{
    static const char *const take[] = { NULL, ".x", ".xy", ".rgb" };
    int ww = ir_type_width(want), hw = ir_type_width(v->type);
    if (v->kind != SG_V_PATH || ww < 1 || ww > 3 || hw <= ww)
        return;
    sg_hint(c->d, "write '%s' after it to take its first %d component%s", take[ww], ww,
            ww == 1 ? "" : "s");
}

/* Output port index of node `n` called `port`, or -1. */
static int node_port(checker *c, const sg_node *n, const char *port)
{
    if (n->kind == SG_NODE_INSTANCE) {
        const sg_shader *callee = c->p->shaders[n->shader];
        for (int i = 0; i < callee->nouts; i++)
            if (!strcmp(callee->outs[i].name, port))
                return i;
        return -1;
    }
    return !strcmp(port, "out") ? 0 : -1;
}

static int node_noutputs(checker *c, const sg_node *n)
{
    if (n->kind == SG_NODE_INSTANCE)
        return c->p->shaders[n->shader]->nouts;
    return n->kind == SG_NODE_UNRESOLVED ? 0 : 1;
}

/* `n` or `n.port` for local node `node`: its output index into v (a
 * swizzle `d.r` is `d.out.r` when r is not a port of d); *rest past the
 * parts used. */
static bool node_ref(checker *c, sg_value *v, int node, int *rest)
{
    sg_node *n = &c->s->nodes[node];
    v->ref = SG_REF_NODE;
    v->node = node;
    v->index = 0;
    if (n->kind == SG_NODE_UNRESOLVED)
        return false;               /* already reported */
    int nout = node_noutputs(c, n);
    if (v->nparts == 1) {
        if (nout != 1) {
            char msg[300];
            snprintf(msg, sizeof msg, "node '%s' has %d outputs: write '%s.<output>'",
                     n->name, nout, n->name);
            sg_error(c->d, v->loc, SG_E_BAD_REFERENCE, msg);
            return false;
        }
    } else {
        int port = node_port(c, n, v->parts[1]);
        int dummy;
        if (port >= 0) {
            v->index = port;
            *rest = 2;
        } else if (swizzle_ok(v->parts[1], &dummy) &&
                   (node_port(c, n, "out") >= 0 || nout == 1)) {
            /* `d.r` is `d.out.r` when r is not a port of d */
            v->index = node_port(c, n, "out") >= 0 ? node_port(c, n, "out") : 0;
        } else {
            sg_error(c->d, v->loc, SG_E_UNKNOWN_PORT, n->name, "output", v->parts[1]);
            if (n->kind == SG_NODE_INSTANCE) {
                const sg_shader *callee = c->p->shaders[n->shader];
                sg_hint_suggest(c->d, rs_near_port(callee->outs, callee->nouts, v->parts[1]));
            } else {
                sg_suggest sg;
                sg_suggest_init(&sg, v->parts[1]);
                sg_suggest_offer(&sg, "out");
                sg_hint_suggest(c->d, sg_suggest_best(&sg));
            }
            return false;
        }
    }
    return true;
}

/* vector.NAME[.across] */
static bool vector_ref(checker *c, sg_value *v, int *rest)
{
    char buf[256];
    /* vector.NAME: the scene's spline or polygon NAME as a mask;
     * vector.NAME.across: 0 on its centre line (or inside the
     * polygon), 1 at the outer edge of its falloff and beyond.  The
     * scene checks that NAME is one of its shapes (scene.c). */
    v->ref = SG_REF_VECTOR;
    v->index = 0;
    v->type = IR_T_FLOAT;
    *rest = 2;
    if (v->nparts >= 3 && !strcmp(v->parts[2], "across")) {
        v->index = 1;
        *rest = 3;
    } else if (v->nparts >= 3 && strcmp(v->parts[2], "x") && strcmp(v->parts[2], "r")) {
        char msg[300];
        snprintf(msg, sizeof msg, "'%s' is not a part of a vector shape (vector.NAME is "
                 "its mask, vector.NAME.across its distance across) in '%s'",
                 v->parts[2], path_text(v, buf, sizeof buf));
        sg_error(c->d, v->loc, SG_E_BAD_REFERENCE, msg);
        return false;
    }
    return true;
}

/* Resolve what a value names (not yet its type when it is a node output).
 * In scope: nodes (if allow_nodes), inputs, params, textures, terrain
 * inputs.  Returns false (with a diagnostic) if it names nothing. */
bool rs_resolve_path(checker *c, sg_value *v, bool allow_locals)
{
    v->type = IR_T_ERROR;
    switch (v->kind) {
    case SG_V_NUMBER: v->type = IR_T_FLOAT; return true;
    case SG_V_VEC:    v->type = ir_type_vec(v->width); return true;
    case SG_V_STRING: v->type = IR_T_TEX; return true;
    case SG_V_PATH:   break;
    default:          return false;
    }
    char buf[256];
    const char *first = v->parts[0];
    int rest = 1;                       /* index of the first unused part */
    int local = allow_locals ? sg_map_get(&c->locals, first) : -1;
    if (local >= 0 && (local & 3) == L_NODE) {
        if (!node_ref(c, v, local >> 2, &rest))
            return false;
    } else if (local >= 0) {
        v->ref = (local & 3) == L_IN ? SG_REF_IN : SG_REF_PARAM;
        v->index = local >> 2;
    } else if (sg_map_get(&c->p->globals, first) >= 0 &&
               (sg_map_get(&c->p->globals, first) & 1) == SG_G_TEXTURE) {
        v->ref = SG_REF_TEXTURE;
        v->index = sg_map_get(&c->p->globals, first) >> 1;
        v->type = IR_T_TEX;
    } else if (!strcmp(first, "vector") && v->nparts >= 2) {
        if (!vector_ref(c, v, &rest))
            return false;
    } else if ((!strcmp(first, "terrain") || !strcmp(first, "view")) && v->nparts >= 2) {
        snprintf(buf, sizeof buf, "%s.%s", first, v->parts[1]);
        int in = ir_input_by_name(buf);
        if (in < 0) {
            sg_error(c->d, v->loc, SG_E_UNKNOWN_NAME, buf);
            sg_hint_suggest(c->d, near_name(c, buf, allow_locals));
            return false;
        }
        v->ref = SG_REF_INPUT;
        v->index = in;
        v->type = ir_input_get((ir_input_kind)in)->type;
        rest = 2;
    } else {
        if (!allow_locals && sg_map_get(&c->locals, first) >= 0) {
            char msg[300];
            snprintf(msg, sizeof msg, "a default value cannot use '%s': only constants, "
                     "textures and terrain inputs", first);
            sg_error(c->d, v->loc, SG_E_BAD_DEFAULT, msg);
        } else if (!rs_after_failed_import(c)) {
            sg_error(c->d, v->loc, SG_E_UNKNOWN_NAME, path_text(v, buf, sizeof buf));
            sg_hint_suggest(c->d, near_name(c, first, allow_locals));
        }
        return false;
    }
    if (rest < v->nparts) {
        int dummy;
        if (rest + 1 < v->nparts || !swizzle_ok(v->parts[rest], &dummy)) {
            char msg[300];
            snprintf(msg, sizeof msg, "'%s' is not a swizzle (x y z w or r g b a, "
                     "up to 4) in '%s'", v->parts[rest], path_text(v, buf, sizeof buf));
            sg_error(c->d, v->loc, SG_E_BAD_SWIZZLE, msg);
            return false;
        }
        v->swizzle = v->parts[rest];
    }
    if (v->ref == SG_REF_IN)
        v->type = rs_apply_swizzle(c, v, c->s->ins[v->index].type);
    else if (v->ref == SG_REF_PARAM)
        v->type = rs_apply_swizzle(c, v, c->s->params[v->index].type);
    else if (v->ref != SG_REF_NODE)
        v->type = rs_apply_swizzle(c, v, v->type);
    return true;
}
