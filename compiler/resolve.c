/* resolve.c — names, ports, types, cycles and nesting depth.
 *
 * After parsing every file of a program:
 *  1. top-level names (shaders, materials, textures) go into one global
 *     map; a second definition is DUPLICATE, pointing at the first;
 *  2. per shader, a local scope (inputs, params, nodes); node types are
 *     looked up (terrain inputs, `painted`, the IR op table, instance
 *     shaders) and every value's path is resolved to what it names;
 *  3. cycles among nodes of one scope and among shaders instantiating
 *     each other are found by an iterative DFS (so a 100 000-node chain
 *     cannot overflow the stack) and reported with their path;
 *  4. nodes are type-checked in dependency order.  Built-in ops use the op
 *     table's type rule (the IR builder's rule, so the two cannot
 *     disagree); a float operand of a componentwise op is splatted to the
 *     others' width.  Everywhere else types match exactly, except that a
 *     float literal splats into a vecN port;
 *  5. the instance nesting depth of every shader is computed; deeper than
 *     SG_MAX_DEPTH is TOO_DEEP (lowering recurses once per level).
 *
 * Example: in
 *     node n : sub { a = x, b = lo }
 *     node r : div { a = n.out, b = d.out }
 * `n.out` resolves to (SG_REF_NODE, node n, output 0), r depends on n and
 * d, and r's type is div's rule applied to (float, float) = float. */
#include "sg_internal.h"
#include "util.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <stb_image.h>

const char *const sg_output_names[SG_OUT_COUNT] = {
#define X(id, name, type) name,
    SG_OUTPUTS(X)
#undef X
};

static const ir_type output_types[SG_OUT_COUNT] = {
#define X(id, name, type) type,
    SG_OUTPUTS(X)
#undef X
};

int sg_shader_find(const sg_program *p, const char *name)
{
    int g = sg_map_get(&p->globals, name);
    if (g < 0 || (g & 1) != SG_G_SHADER || p->shaders[g >> 1]->is_material)
        return -1;
    return g >> 1;
}

ir_type sg_node_output_type(const sg_program *p, const sg_shader *s,
                            const sg_node *n, int index)
{
    switch (n->kind) {
    case SG_NODE_OP:
    case SG_NODE_INPUT:
    case SG_NODE_PAINTED:
        return index == 0 ? n->out_type : IR_T_ERROR;
    case SG_NODE_INSTANCE: {
        const sg_shader *c = p->shaders[n->shader];
        return index < c->nouts ? c->outs[index].type : IR_T_ERROR;
    }
    default:
        return IR_T_ERROR;
    }
}

/* ---- helpers ------------------------------------------------------------ */

typedef struct checker {
    sg_program *p;
    sg_diags   *d;
    sg_shader  *s;        /* current scope                                */
    sg_map      locals;   /* name -> (index << 2) | local kind            */
    int         suppressed; /* unknown names left unreported in this scope:
                               an import failed, they may be its (parse.c) */
} checker;

/* An unknown global name (node type, texture, material, compositor) is
 * most likely one of a failed import's: leave it out, the import's error
 * says what to do.  The scope is then not ok, though no error is added. */
static bool after_failed_import(checker *c)
{
    if (c->p->failed_imports == 0)
        return false;
    c->suppressed++;
    return true;
}

enum { L_NODE, L_IN, L_PARAM };

static void duplicate(checker *c, sg_loc loc, const char *what, const char *name,
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
static ir_type apply_swizzle(checker *c, sg_value *v, ir_type base)
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
static const char *near_node_type(checker *c, const char *word)
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

static const char *near_port(const sg_port *ports, int n, const char *word)
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
static void hint_swizzle(checker *c, const sg_value *v, ir_type want)
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

/* Resolve what a value names (not yet its type when it is a node output).
 * In scope: nodes (if allow_nodes), inputs, params, textures, terrain
 * inputs.  Returns false (with a diagnostic) if it names nothing. */
static bool resolve_path(checker *c, sg_value *v, bool allow_locals)
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
        sg_node *n = &c->s->nodes[local >> 2];
        v->ref = SG_REF_NODE;
        v->node = local >> 2;
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
                rest = 2;
            } else if (swizzle_ok(v->parts[1], &dummy) &&
                       (node_port(c, n, "out") >= 0 || nout == 1)) {
                /* `d.r` is `d.out.r` when r is not a port of d */
                v->index = node_port(c, n, "out") >= 0 ? node_port(c, n, "out") : 0;
            } else {
                sg_error(c->d, v->loc, SG_E_UNKNOWN_PORT, n->name, "output", v->parts[1]);
                if (n->kind == SG_NODE_INSTANCE) {
                    const sg_shader *callee = c->p->shaders[n->shader];
                    sg_hint_suggest(c->d, near_port(callee->outs, callee->nouts, v->parts[1]));
                } else {
                    sg_suggest sg;
                    sg_suggest_init(&sg, v->parts[1]);
                    sg_suggest_offer(&sg, "out");
                    sg_hint_suggest(c->d, sg_suggest_best(&sg));
                }
                return false;
            }
        }
    } else if (local >= 0) {
        v->ref = (local & 3) == L_IN ? SG_REF_IN : SG_REF_PARAM;
        v->index = local >> 2;
    } else if (sg_map_get(&c->p->globals, first) >= 0 &&
               (sg_map_get(&c->p->globals, first) & 1) == SG_G_TEXTURE) {
        v->ref = SG_REF_TEXTURE;
        v->index = sg_map_get(&c->p->globals, first) >> 1;
        v->type = IR_T_TEX;
    } else if (!strcmp(first, "vector") && v->nparts >= 2) {
        /* vector.NAME: the scene's spline or polygon NAME as a mask;
         * vector.NAME.across: 0 on its centre line (or inside the
         * polygon), 1 at the outer edge of its falloff and beyond.  The
         * scene checks that NAME is one of its shapes (scene.c). */
        v->ref = SG_REF_VECTOR;
        v->index = 0;
        v->type = IR_T_FLOAT;
        rest = 2;
        if (v->nparts >= 3 && !strcmp(v->parts[2], "across")) {
            v->index = 1;
            rest = 3;
        } else if (v->nparts >= 3 && strcmp(v->parts[2], "x") && strcmp(v->parts[2], "r")) {
            char msg[300];
            snprintf(msg, sizeof msg, "'%s' is not a part of a vector shape (vector.NAME is "
                     "its mask, vector.NAME.across its distance across) in '%s'",
                     v->parts[2], path_text(v, buf, sizeof buf));
            sg_error(c->d, v->loc, SG_E_BAD_REFERENCE, msg);
            return false;
        }
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
        } else if (!after_failed_import(c)) {
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
        v->type = apply_swizzle(c, v, c->s->ins[v->index].type);
    else if (v->ref == SG_REF_PARAM)
        v->type = apply_swizzle(c, v, c->s->params[v->index].type);
    else if (v->ref != SG_REF_NODE)
        v->type = apply_swizzle(c, v, v->type);
    return true;
}

/* ---- the op type rule with splatting ------------------------------------ */

/* The op's result type for `args` (splatting float operands of a
 * componentwise op to the widest operand; splat[i] says to what). */
static ir_type op_result(const ir_opinfo *info, const ir_type *args, int n,
                         ir_type *splat)
{
    ir_type t[4];
    int maxw = 0;
    for (int i = 0; i < n; i++) {
        t[i] = args[i];
        if (splat)
            splat[i] = IR_T_ERROR;
        if (ir_type_width(args[i]) > maxw)
            maxw = ir_type_width(args[i]);
    }
    if ((info->flags & IR_COMPONENTWISE) && maxw > 1)
        for (int i = 0; i < n; i++)
            if (args[i] == IR_T_FLOAT) {
                t[i] = ir_type_vec(maxw);
                if (splat)
                    splat[i] = t[i];
            }
    return info->type(t, n);
}

static const char *type_list(const ir_type *t, int n, char *buf, size_t size)
{
    size_t o = (size_t)snprintf(buf, size, "(");
    for (int i = 0; i < n && o < size; i++)
        o += (size_t)snprintf(buf + o, size - o, "%s%s", i ? ", " : "", ir_type_name(t[i]));
    if (o < size)
        snprintf(buf + o, size - o, ")");
    return buf;
}

static void check_op(checker *c, sg_node *n)
{
    const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
    int nargs = info->nargs;
    sg_binding *slot[4] = { 0 };
    bool bad = false, unknown = false;
    for (int i = 0; i < n->nargs; i++) {
        sg_binding *b = &n->args[i];
        int k = -1;
        for (int j = 0; j < nargs; j++)
            if (info->ports[j] && !strcmp(info->ports[j], b->port))
                k = j;
        if (k < 0) {
            sg_error(c->d, b->loc, SG_E_UNKNOWN_PORT, n->type, "input", b->port);
            sg_suggest sg;
            sg_suggest_init(&sg, b->port);
            for (int j = 0; j < nargs; j++)
                sg_suggest_offer(&sg, info->ports[j]);
            sg_hint_suggest(c->d, sg_suggest_best(&sg));
            bad = unknown = true;
            continue;
        }
        if (slot[k]) {
            duplicate(c, b->loc, "port", b->port, slot[k]->loc);
            bad = true;
            continue;
        }
        slot[k] = b;
        b->slot = k;
        if (b->val.type == IR_T_ERROR)
            bad = true;
    }
    for (int j = 0; j < nargs; j++)
        if (!slot[j]) {
            if (!unknown && !n->incomplete)    /* otherwise already reported */
                sg_error(c->d, n->loc, SG_E_MISSING_INPUT, n->name, info->ports[j]);
            bad = true;
        }
    if (bad)
        return;
    ir_type args[4], splat[4];
    for (int j = 0; j < nargs; j++)
        args[j] = slot[j]->val.type;
    ir_type r = op_result(info, args, nargs, splat);
    if (r != IR_T_ERROR) {
        for (int j = 0; j < nargs; j++)
            slot[j]->splat = splat[j];
        n->out_type = r;
        return;
    }
    /* Which operand is wrong?  The last one that some other type would
     * make acceptable, trying the other operands' types first. */
    char what[200], buf[100];
    for (int j = nargs - 1; j >= 0; j--) {
        ir_type cand[4 + IR_T_COUNT];
        int ncand = 0;
        for (int k = 0; k < nargs; k++)
            if (k != j)
                cand[ncand++] = args[k];
        for (int t = IR_T_FLOAT; t < IR_T_COUNT; t++)
            cand[ncand++] = (ir_type)t;
        for (int k = 0; k < ncand; k++) {
            if (cand[k] == args[j])
                continue;
            ir_type try[4];
            memcpy(try, args, sizeof try);
            try[j] = cand[k];
            if (op_result(info, try, nargs, NULL) != IR_T_ERROR) {
                snprintf(what, sizeof what, "port '%s' of '%s' (%s)", info->ports[j],
                         n->name, n->type);
                sg_error(c->d, slot[j]->val.loc, SG_E_TYPE_MISMATCH, what,
                         ir_type_name(cand[k]), ir_type_name(args[j]));
                hint_swizzle(c, &slot[j]->val, cand[k]);
                return;
            }
        }
    }
    snprintf(what, sizeof what, "'%s' (%s)", n->name, n->type);
    sg_error(c->d, n->loc, SG_E_TYPE_MISMATCH, what, "operands it accepts",
             type_list(args, nargs, buf, sizeof buf));
}

/* A value into a port of declared type `want`: exact, or a float literal
 * into vecN (sets *splat). */
static bool assignable(const sg_value *v, ir_type want, ir_type *splat)
{
    *splat = IR_T_ERROR;
    if (v->type == want)
        return true;
    if (v->kind == SG_V_NUMBER && ir_type_width(want) > 1) {
        *splat = want;
        return true;
    }
    return false;
}

static void check_instance(checker *c, sg_node *n)
{
    sg_shader *callee = c->p->shaders[n->shader];
    sg_binding **slot = calloc((size_t)callee->nins + 1, sizeof *slot);
    bool unknown = false;
    if (!slot)
        abort();
    for (int i = 0; i < n->nargs; i++) {
        sg_binding *b = &n->args[i];
        int k = -1;
        for (int j = 0; j < callee->nins; j++)
            if (!strcmp(callee->ins[j].name, b->port))
                k = j;
        if (k < 0) {
            sg_error(c->d, b->loc, SG_E_UNKNOWN_PORT, n->type, "input", b->port);
            sg_hint_suggest(c->d, near_port(callee->ins, callee->nins, b->port));
            unknown = true;
            continue;
        }
        if (slot[k]) {
            duplicate(c, b->loc, "port", b->port, slot[k]->loc);
            continue;
        }
        slot[k] = b;
        b->slot = k;
        if (b->val.type == IR_T_ERROR)
            continue;
        if (!assignable(&b->val, callee->ins[k].type, &b->splat)) {
            char what[200];
            snprintf(what, sizeof what, "input '%s' of '%s' (%s)", b->port, n->name, n->type);
            sg_error(c->d, b->val.loc, SG_E_TYPE_MISMATCH, what,
                     ir_type_name(callee->ins[k].type), ir_type_name(b->val.type));
            hint_swizzle(c, &b->val, callee->ins[k].type);
        }
    }
    for (int j = 0; j < callee->nins; j++)
        if (!slot[j] && !callee->ins[j].has_value && !unknown && !n->incomplete)
            sg_error(c->d, n->loc, SG_E_MISSING_INPUT, n->name, callee->ins[j].name);
    free(slot);
}

static void check_painted(checker *c, sg_node *n)
{
    n->out_type = IR_T_FLOAT;
    bool have = false;
    for (int i = 0; i < n->nargs; i++) {
        sg_binding *b = &n->args[i];
        if (strcmp(b->port, "mask")) {
            sg_error(c->d, b->loc, SG_E_UNKNOWN_PORT, "painted", "input", b->port);
            sg_suggest sg;
            sg_suggest_init(&sg, b->port);
            sg_suggest_offer(&sg, "mask");
            sg_hint_suggest(c->d, sg_suggest_best(&sg));
            continue;
        }
        if (have) {
            duplicate(c, b->loc, "port", b->port, n->args[0].loc);
            continue;
        }
        have = true;
        b->slot = 0;
        if (b->val.kind != SG_V_STRING) {
            char what[200];
            snprintf(what, sizeof what, "port 'mask' of '%s' (painted)", n->name);
            sg_error(c->d, b->val.loc, SG_E_TYPE_MISMATCH, what,
                     "a painted mask name in quotes", ir_type_name(b->val.type));
        }
    }
    if (!have && !n->incomplete)
        sg_error(c->d, n->loc, SG_E_MISSING_INPUT, n->name, "mask");
}

/* ---- DFS: cycles and dependency order ------------------------------------ */

typedef struct graph {
    int  n;
    int *start;   /* n + 1 offsets into adj */
    int *adj;
} graph;

typedef void (*cycle_fn)(void *user, const int *path, int len);

/* Post-order (dependencies first) of every vertex; each back edge found
 * calls on_cycle with the path v0 -> … -> vk (-> v0).  Iterative. */
static int *dfs_order(const graph *g, cycle_fn on_cycle, void *user)
{
    int *order = malloc(((size_t)g->n + 1) * sizeof *order);
    int *state = calloc((size_t)g->n + 1, sizeof *state);
    int *pos = malloc(((size_t)g->n + 1) * sizeof *pos);      /* stack index */
    int *stack = malloc(((size_t)g->n + 1) * sizeof *stack);
    int *edge = malloc(((size_t)g->n + 1) * sizeof *edge);
    if (!order || !state || !pos || !stack || !edge)
        abort();
    int norder = 0;
    for (int root = 0; root < g->n; root++) {
        if (state[root])
            continue;
        int sp = 0;
        stack[sp] = root;
        edge[sp] = g->start[root];
        pos[root] = sp++;
        state[root] = 1;
        while (sp) {
            int v = stack[sp - 1];
            if (edge[sp - 1] < g->start[v + 1]) {
                int w = g->adj[edge[sp - 1]++];
                if (state[w] == 0) {
                    stack[sp] = w;
                    edge[sp] = g->start[w];
                    pos[w] = sp++;
                    state[w] = 1;
                } else if (state[w] == 1) {
                    on_cycle(user, stack + pos[w], sp - pos[w]);
                }
            } else {
                state[v] = 2;
                order[norder++] = v;
                sp--;
            }
        }
    }
    free(state);
    free(pos);
    free(stack);
    free(edge);
    return order;
}

typedef struct cycle_ctx {
    checker    *c;
    const char *(*name)(void *names, int i);
    void       *names;
    sg_loc     (*loc)(void *names, int i);
} cycle_ctx;

static void report_cycle(void *user, const int *path, int len)
{
    cycle_ctx *cc = user;
    size_t n = 1;
    for (int i = 0; i < len; i++)
        n += strlen(cc->name(cc->names, path[i])) + 4;
    n += strlen(cc->name(cc->names, path[0]));
    char *msg = xmalloc(n);
    msg[0] = 0;
    for (int i = 0; i < len; i++) {
        strcat(msg, cc->name(cc->names, path[i]));
        strcat(msg, " -> ");
    }
    strcat(msg, cc->name(cc->names, path[0]));
    sg_error(cc->c->d, cc->loc(cc->names, path[0]), SG_E_CYCLE, msg);
    free(msg);
}

static const char *node_name(void *s, int i) { return ((sg_shader *)s)->nodes[i].name; }
static sg_loc node_loc(void *s, int i) { return ((sg_shader *)s)->nodes[i].loc; }
static const char *shader_name(void *p, int i) { return ((sg_program *)p)->shaders[i]->name; }
static sg_loc shader_loc(void *p, int i) { return ((sg_program *)p)->shaders[i]->loc; }

/* ---- per shader ---------------------------------------------------------- */

static void declare_locals(checker *c, sg_shader *s)
{
    sg_map_free(&c->locals);
    c->s = s;
    struct { sg_port *ports; int n; int kind; const char *what; } groups[] = {
        { s->ins, s->nins, L_IN, "input" },
        { s->params, s->nparams, L_PARAM, "param" },
    };
    for (int g = 0; g < 2; g++)
        for (int i = 0; i < groups[g].n; i++) {
            sg_port *port = &groups[g].ports[i];
            int old = sg_map_put(&c->locals, port->name, i << 2 | groups[g].kind);
            if (old >= 0) {
                sg_loc first = (old & 3) == L_IN ? s->ins[old >> 2].loc : s->params[old >> 2].loc;
                duplicate(c, port->loc, groups[g].what, port->name, first);
            }
        }
    for (int i = 0; i < s->nnodes; i++) {
        sg_node *n = &s->nodes[i];
        int old = sg_map_put(&c->locals, n->name, i << 2 | L_NODE);
        if (old >= 0) {
            sg_loc first = (old & 3) == L_IN ? s->ins[old >> 2].loc
                         : (old & 3) == L_PARAM ? s->params[old >> 2].loc
                         : s->nodes[old >> 2].loc;
            duplicate(c, n->loc, "node", n->name, first);
        }
    }
    sg_map m = { 0 };
    for (int i = 0; i < s->nouts; i++) {
        int old = sg_map_put(&m, s->outs[i].name, i);
        if (old >= 0)
            duplicate(c, s->outs[i].loc, "output", s->outs[i].name, s->outs[old].loc);
    }
    sg_map_free(&m);
}

static void resolve_node_type(checker *c, sg_node *n)
{
    int in = ir_input_by_name(n->type);
    if (in >= 0) {
        n->kind = SG_NODE_INPUT;
        n->op = in;
        n->out_type = ir_input_get((ir_input_kind)in)->type;
        if (n->nargs)
            sg_error(c->d, n->args[0].loc, SG_E_UNKNOWN_PORT, n->type, "input", n->args[0].port);
        return;
    }
    if (!strcmp(n->type, "painted")) {
        n->kind = SG_NODE_PAINTED;
        return;
    }
    int op = ir_op_by_name(n->type);
    if (op >= 0) {
        n->kind = SG_NODE_OP;
        n->op = op;
        return;
    }
    int g = sg_map_get(&c->p->globals, n->type);
    if (g >= 0 && (g & 1) == SG_G_SHADER) {
        sg_shader *s = c->p->shaders[g >> 1];
        if (s->is_material) {
            char msg[300];
            snprintf(msg, sizeof msg, "'%s' is a material; only shaders can be "
                     "instantiated as nodes", s->name);
            sg_error(c->d, n->type_loc, SG_E_BAD_REFERENCE, msg);
            return;
        }
        n->kind = SG_NODE_INSTANCE;
        n->shader = g >> 1;
        return;
    }
    if (after_failed_import(c))
        return;
    sg_error(c->d, n->type_loc, SG_E_UNKNOWN_NODE, n->type);
    sg_hint_suggest(c->d, near_node_type(c, n->type));
}

/* Defaults of inputs and params: constants (params: numbers only),
 * strings and textures (texture inputs), terrain inputs. */
static void check_default(checker *c, sg_port *port, bool is_param)
{
    sg_value *v = &port->value;
    if (is_param && v->kind != SG_V_NUMBER && v->kind != SG_V_VEC) {
        sg_error(c->d, v->loc, SG_E_BAD_DEFAULT,
                 "a param's default must be a number or vecN(...)");
        return;
    }
    if (!resolve_path(c, v, false))
        return;
    ir_type splat;
    if (v->type != IR_T_ERROR && !assignable(v, port->type, &splat)) {
        char what[200];
        snprintf(what, sizeof what, "the default of %s '%s'", is_param ? "param" : "input",
                 port->name);
        sg_error(c->d, v->loc, SG_E_TYPE_MISMATCH, what, ir_type_name(port->type),
                 ir_type_name(v->type));
    }
    if (is_param && port->has_range && !(port->lo <= port->hi)) {
        char msg[200];
        snprintf(msg, sizeof msg, "range of param '%s' is empty (%g > %g)", port->name,
                 port->lo, port->hi);
        sg_error(c->d, v->loc, SG_E_EMPTY_RANGE, msg);
    } else if (is_param && port->has_range && port->lo < port->hi) {
        /* the interval analysis (and the pack's culling) assume the param
         * stays in its range, the default included (lo == hi: fixed at
         * its default, as the IR dump writes a param with no range) */
        int w = v->kind == SG_V_VEC ? v->width : 1;
        for (int k = 0; k < w; k++)
            if (!(v->num[k] >= port->lo && v->num[k] <= port->hi)) {
                char msg[300];
                snprintf(msg, sizeof msg, "the default %g of param '%s' is outside its "
                         "range [%g, %g] (the compiler assumes the param stays in it)",
                         v->num[k], port->name, port->lo, port->hi);
                sg_error(c->d, v->loc, SG_E_BAD_DEFAULT, msg);
                break;
            }
    }
}

static void check_shader(checker *c, sg_shader *s)
{
    int errors = c->d->nerrors;
    c->suppressed = 0;
    declare_locals(c, s);
    for (int i = 0; i < s->nins; i++)
        if (s->ins[i].has_value)
            check_default(c, &s->ins[i], false);
    for (int i = 0; i < s->nparams; i++)
        check_default(c, &s->params[i], true);
    for (int i = 0; i < s->nnodes; i++)
        resolve_node_type(c, &s->nodes[i]);

    /* names in node inputs; dependency edges */
    graph g = { s->nnodes, calloc((size_t)s->nnodes + 1, sizeof(int)), NULL };
    if (!g.start)
        abort();
    int nedges = 0;
    for (int i = 0; i < s->nnodes; i++) {
        sg_node *n = &s->nodes[i];
        for (int j = 0; j < n->nargs; j++) {
            sg_value *v = &n->args[j].val;
            n->args[j].splat = IR_T_ERROR;
            if (n->kind == SG_NODE_PAINTED && v->kind == SG_V_STRING)
                continue;
            resolve_path(c, v, true);
            /* an edge even if the path was bad after naming a node */
            if (v->kind == SG_V_PATH && v->ref == SG_REF_NODE)
                nedges++;
        }
    }
    g.adj = xmalloc(((size_t)nedges + 1) * sizeof *g.adj);
    for (int i = 0, e = 0; i < s->nnodes; i++) {
        g.start[i] = e;
        for (int j = 0; j < s->nodes[i].nargs; j++) {
            sg_value *v = &s->nodes[i].args[j].val;
            if (v->kind == SG_V_PATH && v->ref == SG_REF_NODE)
                g.adj[e++] = v->node;
        }
        g.start[i + 1] = e;
    }
    cycle_ctx cc = { c, node_name, s, node_loc };
    int errors_before_cycles = c->d->nerrors;
    s->order = dfs_order(&g, report_cycle, &cc);
    s->norder = s->nnodes;
    free(g.start);
    free(g.adj);

    /* types, dependencies first (skipped if there is a cycle: the order
     * would not be one) */
    bool cyclic = c->d->nerrors != errors_before_cycles;
    if (!cyclic) {
        for (int k = 0; k < s->norder; k++) {
            sg_node *n = &s->nodes[s->order[k]];
            for (int j = 0; j < n->nargs; j++) {
                sg_value *v = &n->args[j].val;
                if (v->kind == SG_V_PATH && v->ref == SG_REF_NODE) {
                    const sg_node *src = &s->nodes[v->node];
                    v->type = apply_swizzle(c, v, sg_node_output_type(c->p, s, src, v->index));
                }
            }
            switch (n->kind) {
            case SG_NODE_OP:       check_op(c, n); break;
            case SG_NODE_INSTANCE: check_instance(c, n); break;
            case SG_NODE_PAINTED:  check_painted(c, n); break;
            default:               break;
            }
        }
    }

    /* outputs */
    for (int i = 0; i < s->nouts; i++) {
        sg_port *o = &s->outs[i];
        ir_type want = o->type;
        if (s->is_material) {
            o->output = -1;
            for (int k = 0; k < SG_OUT_COUNT; k++)
                if (!strcmp(o->name, sg_output_names[k]))
                    o->output = k;
            if (o->output < 0) {
                sg_error(c->d, o->loc, SG_E_BAD_OUTPUT, o->name);
                sg_suggest sg;
                sg_suggest_init(&sg, o->name);
                for (int k = 0; k < SG_OUT_COUNT; k++)
                    sg_suggest_offer(&sg, sg_output_names[k]);
                sg_hint_suggest(c->d, sg_suggest_best(&sg));
                continue;
            }
            want = output_types[o->output];
            if (o->type != IR_T_ERROR && o->type != want) {
                char what[100];
                snprintf(what, sizeof what, "material output '%s'", o->name);
                sg_error(c->d, o->loc, SG_E_TYPE_MISMATCH, what, ir_type_name(want),
                         ir_type_name(o->type));
                continue;
            }
            o->type = want;
        }
        sg_value *v = &o->value;
        if (!resolve_path(c, v, true))
            continue;
        if (v->ref == SG_REF_NODE)
            v->type = apply_swizzle(c, v, sg_node_output_type(c->p, s, &s->nodes[v->node],
                                                              v->index));
        ir_type splat;
        if (v->type != IR_T_ERROR && !assignable(v, want, &splat)) {
            char what[100];
            snprintf(what, sizeof what, "output '%s'", o->name);
            sg_error(c->d, v->loc, SG_E_TYPE_MISMATCH, what, ir_type_name(want),
                     ir_type_name(v->type));
            hint_swizzle(c, v, want);
        }
    }
    s->ok = c->d->nerrors == errors && c->suppressed == 0;
}

/* ---- the program ---------------------------------------------------------- */

static void declare_globals(checker *c)
{
    sg_program *p = c->p;
    /* in file order, shaders and textures interleaved as they appear is not
     * needed: duplicates are reported at the later definition by location */
    for (int i = 0; i < p->nshaders; i++) {
        sg_shader *s = p->shaders[i];
        if (ir_op_by_name(s->name) >= 0 || !strcmp(s->name, "painted")) {
            char msg[200];
            snprintf(msg, sizeof msg, "'%s' is a built-in node type and cannot be redefined",
                     s->name);
            sg_error(c->d, s->loc, SG_E_REDEFINED, msg);
            continue;
        }
        int old = sg_map_put(&p->globals, s->name, i << 1 | SG_G_SHADER);
        if (old >= 0)
            duplicate(c, s->loc, s->is_material ? "material" : "shader", s->name,
                      (old & 1) ? p->textures[old >> 1]->loc : p->shaders[old >> 1]->loc);
    }
    for (int i = 0; i < p->ntextures; i++) {
        sg_texdecl *t = p->textures[i];
        int old = sg_map_put(&p->globals, t->name, i << 1 | SG_G_TEXTURE);
        if (old >= 0)
            duplicate(c, t->loc, "texture", t->name,
                      (old & 1) ? p->textures[old >> 1]->loc : p->shaders[old >> 1]->loc);
    }
}

/* Cycles among shaders instantiating each other, and nesting depth. */
static void check_nesting(checker *c)
{
    sg_program *p = c->p;
    graph g = { p->nshaders, calloc((size_t)p->nshaders + 1, sizeof(int)), NULL };
    if (!g.start)
        abort();
    int nedges = 0;
    for (int i = 0; i < p->nshaders; i++)
        for (int j = 0; j < p->shaders[i]->nnodes; j++)
            nedges += p->shaders[i]->nodes[j].kind == SG_NODE_INSTANCE;
    g.adj = xmalloc(((size_t)nedges + 1) * sizeof *g.adj);
    for (int i = 0, e = 0; i < p->nshaders; i++) {
        g.start[i] = e;
        for (int j = 0; j < p->shaders[i]->nnodes; j++)
            if (p->shaders[i]->nodes[j].kind == SG_NODE_INSTANCE)
                g.adj[e++] = p->shaders[i]->nodes[j].shader;
        g.start[i + 1] = e;
    }
    cycle_ctx cc = { c, shader_name, p, shader_loc };
    int *order = dfs_order(&g, report_cycle, &cc);
    int *done = xcalloc((size_t)p->nshaders + 1, sizeof *done);
    for (int k = 0; k < p->nshaders; k++) {
        int v = order[k];
        int depth = 0;
        for (int e = g.start[v]; e < g.start[v + 1]; e++)
            if (done[g.adj[e]] && p->shaders[g.adj[e]]->depth + 1 > depth)
                depth = p->shaders[g.adj[e]]->depth + 1;
        p->shaders[v]->depth = depth;
        done[v] = 1;
        if (depth == SG_MAX_DEPTH + 1)
            sg_error(c->d, p->shaders[v]->loc, SG_E_TOO_DEEP, SG_MAX_DEPTH);
    }
    free(done);
    free(order);
    free(g.start);
    free(g.adj);
}

static void check_scene(checker *c)
{
    sg_program *p = c->p;
    const sg_scene *sc = p->scene;
    if (!sc)
        return;
    for (int i = 0; i < sc->nmaterials; i++)
        if (sg_material_find(p, sc->materials[i]) < 0) {
            int g = sg_map_get(&p->globals, sc->materials[i]);
            if (g >= 0) {
                char msg[300];
                snprintf(msg, sizeof msg, "'%s' is not a material", sc->materials[i]);
                sg_error(c->d, sc->material_locs[i], SG_E_BAD_REFERENCE, msg);
            } else if (!after_failed_import(c)) {
                sg_error(c->d, sc->material_locs[i], SG_E_UNKNOWN_NAME, sc->materials[i]);
                sg_suggest sg;
                sg_suggest_init(&sg, sc->materials[i]);
                for (int k = 0; k < p->nmaterials; k++)
                    sg_suggest_offer(&sg, p->shaders[p->materials[k]]->name);
                sg_hint_suggest(c->d, sg_suggest_best(&sg));
            }
        }
    if (sg_shader_find(p, sc->compositor) < 0 && !after_failed_import(c)) {
        char msg[300];
        snprintf(msg, sizeof msg, "compositor '%s' is not a shader of this program "
                 "(import \"nodes/compositors.sg\"?)", sc->compositor);
        sg_error(c->d, sc->compositor_loc, SG_E_UNDECLARED, msg);
        sg_suggest sg;
        sg_suggest_init(&sg, sc->compositor);
        for (int k = 0; k < p->nshaders; k++)
            if (!p->shaders[k]->is_material)
                sg_suggest_offer(&sg, p->shaders[k]->name);
        sg_hint_suggest(c->d, sg_suggest_best(&sg));
    }
}

void sg_resolve(sg_program *p, sg_diags *d)
{
    checker c = { p, d, NULL, { 0 }, 0 };
    declare_globals(&c);
    for (int i = 0; i < p->nshaders; i++)
        check_shader(&c, p->shaders[i]);
    sg_map_free(&c.locals);
    check_nesting(&c);
    check_scene(&c);
}

/* ---- texture files ----------------------------------------------------------- */

typedef void (*tex_fn)(void *user, const char *file, sg_loc loc);

/* Every texture file named in the program, with where: declarations,
 * then inline strings on node ports and input defaults, in file order. */
static void each_texture_file(const sg_program *p, tex_fn fn, void *user)
{
    for (int i = 0; i < p->ntextures; i++) {
        const sg_texdecl *t = p->textures[i];
        if (t->file && *t->file)
            fn(user, t->file, t->file_loc.line > 0 ? t->file_loc : t->loc);
    }
    for (int i = 0; i < p->nshaders; i++) {
        const sg_shader *s = p->shaders[i];
        const char *dir = p->files[s->file]->dir;
        for (int k = 0; k < s->nins; k++)
            if (s->ins[k].has_value && s->ins[k].value.kind == SG_V_STRING &&
                s->ins[k].type == IR_T_TEX) {
                char *path = splat_path_join(dir, s->ins[k].value.str);
                fn(user, path, s->ins[k].value.loc);
                free(path);
            }
        for (int k = 0; k < s->nnodes; k++) {
            const sg_node *n = &s->nodes[k];
            if (n->kind == SG_NODE_PAINTED)
                continue;
            for (int a = 0; a < n->nargs; a++)
                if (n->args[a].val.kind == SG_V_STRING) {
                    char *path = splat_path_join(dir, n->args[a].val.str);
                    fn(user, path, n->args[a].val.loc);
                    free(path);
                }
        }
    }
}

typedef struct tex_find { const char *file; sg_loc loc; } tex_find;

static void find_file(void *user, const char *file, sg_loc loc)
{
    tex_find *f = user;
    if (f->loc.line == 0 && !strcmp(f->file, file))
        f->loc = loc;
}

sg_loc sg_texture_file_loc(const sg_program *p, const char *file)
{
    tex_find f = { file, { NULL, 0, 0 } };
    each_texture_file(p, find_file, &f);
    return f.loc;
}

typedef struct tex_check {
    sg_diags *d;
    sg_map    seen;
    char    **keys;
    int       nkeys, cap;
    bool      ok;
} tex_check;

static void check_file(void *user, const char *file, sg_loc loc)
{
    tex_check *c = user;
    if (sg_map_get(&c->seen, file) >= 0)
        return;
    if (c->nkeys == c->cap) {
        c->cap = c->cap ? 2 * c->cap : 16;
        c->keys = xrealloc(c->keys, (size_t)c->cap * sizeof *c->keys);
    }
    c->keys[c->nkeys] = xstrdup(file);
    sg_map_put(&c->seen, c->keys[c->nkeys++], 0);
    /* opened as every input is (util.h): a FIFO or device is refused, not read */
    char why[256];
    int w, h, comp;
    FILE *f = splat_input_fopen(file, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f) {
        sg_error(c->d, loc, SG_E_IO, file, why);
        c->ok = false;
        return;
    }
    if (!stbi_info_from_file(f, &w, &h, &comp)) {
        sg_error(c->d, loc, SG_E_IO, file, "not an image (PNG, JPEG, TGA or BMP)");
        c->ok = false;
    }
    fclose(f);
}

bool sg_check_texture_files(const sg_program *p, sg_diags *d)
{
    tex_check c = { d, { 0 }, NULL, 0, 0, true };
    each_texture_file(p, check_file, &c);
    sg_map_free(&c.seen);
    for (int i = 0; i < c.nkeys; i++)
        free(c.keys[i]);
    free(c.keys);
    return c.ok;
}
