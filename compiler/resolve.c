/* resolve.c — names, ports, types, cycles and nesting depth, per shader
 * and for the whole program (names: resolve_names.c, types:
 * resolve_types.c, order: resolve_order.c).
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
#include "resolve.h"
#include "util.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <stb_image.h>

static const ir_type output_types[SG_OUT_COUNT] = {
#define X(id, name, type) type,
    SG_OUTPUTS(X)
#undef X
};


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
                rs_duplicate(c, port->loc, groups[g].what, port->name, first);
            }
        }
    for (int i = 0; i < s->nnodes; i++) {
        sg_node *n = &s->nodes[i];
        int old = sg_map_put(&c->locals, n->name, i << 2 | L_NODE);
        if (old >= 0) {
            sg_loc first = (old & 3) == L_IN ? s->ins[old >> 2].loc
                         : (old & 3) == L_PARAM ? s->params[old >> 2].loc
                         : s->nodes[old >> 2].loc;
            rs_duplicate(c, n->loc, "node", n->name, first);
        }
    }
    sg_map m = { 0 };
    for (int i = 0; i < s->nouts; i++) {
        int old = sg_map_put(&m, s->outs[i].name, i);
        if (old >= 0)
            rs_duplicate(c, s->outs[i].loc, "output", s->outs[i].name, s->outs[old].loc);
    }
    sg_map_free(&m);
}

/* "terrain.X.dx" / ".dy": input X's change to the next pixel right or
 * down (what fwidth lowers to, so `splatc dump` writes it), for the inputs
 * with a derivative accessor; else -1.  The axis in *axis. */
static int derivative_input(const char *type, int *axis)
{
    size_t len = strlen(type);
    if (len < 4 || type[len - 3] != '.' || type[len - 2] != 'd' ||
        (type[len - 1] != 'x' && type[len - 1] != 'y') || len - 3 >= 64)
        return -1;
    char base[64];
    memcpy(base, type, len - 3);
    base[len - 3] = '\0';
    int in = ir_input_by_name(base);
    if (in < 0 || !ir_input_get((ir_input_kind)in)->dglsl)
        return -1;
    *axis = type[len - 1] == 'y';
    return in;
}

static void resolve_node_type(checker *c, sg_node *n)
{
    int axis = 0, in = ir_input_by_name(n->type), din = -1;
    if (in < 0 && (din = derivative_input(n->type, &axis)) >= 0)
        in = din;
    if (in >= 0) {
        n->kind = SG_NODE_INPUT;
        n->op = din >= 0 ? SG_INPUT_DERIVATIVE(in, axis) : in;
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
    if (rs_after_failed_import(c))
        return;
    sg_error(c->d, n->type_loc, SG_E_UNKNOWN_NODE, n->type);
    sg_hint_suggest(c->d, rs_near_node_type(c, n->type));
}

/* Node types in dependency order: operands' types from their sources,
 * then each node's check. */
static void check_types(checker *c, sg_shader *s)
{
    for (int k = 0; k < s->norder; k++) {
        sg_node *n = &s->nodes[s->order[k]];
        for (int j = 0; j < n->nargs; j++) {
            sg_value *v = &n->args[j].val;
            if (v->kind == SG_V_PATH && v->ref == SG_REF_NODE) {
                const sg_node *src = &s->nodes[v->node];
                v->type = rs_apply_swizzle(c, v, sg_node_output_type(c->p, s, src, v->index));
            }
        }
        switch (n->kind) {
        case SG_NODE_OP:       rs_check_op(c, n); break;
        case SG_NODE_INSTANCE: rs_check_instance(c, n); break;
        case SG_NODE_PAINTED:  rs_check_painted(c, n); break;
        default:               break;
        }
    }
}

/* A shader's outputs (a material's: one of SG_OUTPUTS, of its type):
 * resolved and type-checked. */
static void check_outputs(checker *c, sg_shader *s)
{
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
        if (!rs_resolve_path(c, v, true))
            continue;
        if (v->ref == SG_REF_NODE)
            v->type = rs_apply_swizzle(c, v, sg_node_output_type(c->p, s, &s->nodes[v->node],
                                                              v->index));
        ir_type splat;
        if (v->type != IR_T_ERROR && !rs_assignable(v, want, &splat)) {
            char what[100];
            snprintf(what, sizeof what, "output '%s'", o->name);
            sg_error(c->d, v->loc, SG_E_TYPE_MISMATCH, what, ir_type_name(want),
                     ir_type_name(v->type));
            rs_hint_swizzle(c, v, want);
        }
    }
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
    if (!rs_resolve_path(c, v, false))
        return;
    ir_type splat;
    if (v->type != IR_T_ERROR && !rs_assignable(v, port->type, &splat)) {
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
            rs_resolve_path(c, v, true);
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
    s->order = rs_dfs_order(&g, report_cycle, &cc);
    s->norder = s->nnodes;
    free(g.start);
    free(g.adj);

    /* types, dependencies first (skipped if there is a cycle: the order
     * would not be one) */
    bool cyclic = c->d->nerrors != errors_before_cycles;
    if (!cyclic)
        check_types(c, s);
    check_outputs(c, s);
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
            rs_duplicate(c, s->loc, s->is_material ? "material" : "shader", s->name,
                      (old & 1) ? p->textures[old >> 1]->loc : p->shaders[old >> 1]->loc);
    }
    for (int i = 0; i < p->ntextures; i++) {
        sg_texdecl *t = p->textures[i];
        int old = sg_map_put(&p->globals, t->name, i << 1 | SG_G_TEXTURE);
        if (old >= 0)
            rs_duplicate(c, t->loc, "texture", t->name,
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
    int *order = rs_dfs_order(&g, report_cycle, &cc);
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
            } else if (!rs_after_failed_import(c)) {
                sg_error(c->d, sc->material_locs[i], SG_E_UNKNOWN_NAME, sc->materials[i]);
                sg_suggest sg;
                sg_suggest_init(&sg, sc->materials[i]);
                for (int k = 0; k < p->nmaterials; k++)
                    sg_suggest_offer(&sg, p->shaders[p->materials[k]]->name);
                sg_hint_suggest(c->d, sg_suggest_best(&sg));
            }
        }
    if (sg_shader_find(p, sc->compositor) < 0 && !rs_after_failed_import(c)) {
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
