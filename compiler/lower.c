/* lower.c — AST -> IR: sg_lower_material and sg_lower_shader.
 *
 * Instance shaders are inlined: lowering a node that instantiates `ramp`
 * lowers ramp's nodes with ramp's inputs bound to the caller's values.
 * Every node goes through the builder, so identical subtrees (the same
 * instance with the same inputs, twice) are one IR node; an instance met
 * again with the same input refs is not even walked again (memo), which
 * keeps lowering linear in the size of the resulting IR.
 *
 * Params become ir params named "<material>.<param>", textures ir
 * textures (one per declaration or inline file per lowering; opt_dedup
 * merges equal ones), painted masks ir painted masks by scene name.  A
 * float wire into a vecN operand gets ir_splat; a float literal becomes a
 * vecN constant.
 *
 * Before (.sg):
 *     material m {
 *         node s : terrain.slope
 *         node r : ramp { x = s.out, lo = 0.6, hi = 0.8 }
 *         out mask = r.out
 *     }
 * After (IR, ramp inlined; roots m.mask … with defaults for the rest):
 *     node n1 : terrain.slope      node n2 : sub { a = n1.out, b = 0.6 }
 *     node n3 : sub { a = 0.8, b = 0.6 }   node n4 : div { a = n2.out, b = n3.out }
 *     node n5 : saturate { x = n4.out }    out m.mask = n5.out
 */
#include "sg_internal.h"
#include "util.h"

#include <stdlib.h>
#include <string.h>

/* A material whose IR grows beyond this many nodes is OVER_LIMIT (a graph
 * that doubles at every level of nesting would otherwise exhaust memory). */
#define MAX_IR_NODES (1u << 22)

typedef struct memo_entry {
    int     shader;    /* -1 = empty */
    ir_ref *ins;       /* callee nins refs                                  */
    ir_ref *outs;      /* callee nouts refs                                  */
} memo_entry;

typedef struct lowerer {
    sg_program *p;
    ir         *ir;
    sg_diags   *d;
    int        *param_ids;    /* material params -> ir param index         */
    int        *tex_ids;      /* program textures -> ir texture, or -1      */
    sg_map      inline_tex;   /* resolved file -> ir texture index          */
    char      **inline_keys;  /* owned keys of inline_tex                   */
    int         ninline_keys, capinline_keys;
    memo_entry *memo;
    uint32_t    capmemo, nmemo;
    bool        failed;
} lowerer;

/* ---- memo of inlined instances --------------------------------------------- */

static uint32_t memo_hash(int shader, const ir_ref *ins, int n)
{
    uint32_t h = 2166136261u ^ (uint32_t)shader;
    for (int i = 0; i < n; i++)
        h = (h ^ ins[i].id) * 16777619u;
    return h;
}

static memo_entry *memo_find(lowerer *L, int shader, const ir_ref *ins, int n)
{
    if (!L->capmemo)
        return NULL;
    for (uint32_t i = memo_hash(shader, ins, n) & (L->capmemo - 1);; i = (i + 1) & (L->capmemo - 1)) {
        memo_entry *e = &L->memo[i];
        if (e->shader < 0)
            return NULL;
        if (e->shader == shader && (n == 0 || !memcmp(e->ins, ins, (size_t)n * sizeof *ins)))
            return e;
    }
}

static void memo_insert(lowerer *L, int shader, const ir_ref *ins, int nin,
                        const ir_ref *outs, int nout)
{
    if ((L->nmemo + 1) * 2 > L->capmemo) {
        memo_entry *old = L->memo;
        uint32_t oldcap = L->capmemo;
        L->capmemo = oldcap ? oldcap * 2 : 64;
        L->memo = xmalloc(L->capmemo * sizeof *L->memo);
        for (uint32_t i = 0; i < L->capmemo; i++)
            L->memo[i].shader = -1;
        for (uint32_t i = 0; i < oldcap; i++)
            if (old[i].shader >= 0) {
                const sg_shader *s = L->p->shaders[old[i].shader];
                uint32_t j = memo_hash(old[i].shader, old[i].ins, s->nins) & (L->capmemo - 1);
                while (L->memo[j].shader >= 0)
                    j = (j + 1) & (L->capmemo - 1);
                L->memo[j] = old[i];
            }
        free(old);
    }
    uint32_t j = memo_hash(shader, ins, nin) & (L->capmemo - 1);
    while (L->memo[j].shader >= 0)
        j = (j + 1) & (L->capmemo - 1);
    memo_entry *e = &L->memo[j];
    e->shader = shader;
    e->ins = malloc(((size_t)nin + 1) * sizeof *ins);
    e->outs = malloc(((size_t)nout + 1) * sizeof *outs);
    if (!e->ins || !e->outs)
        abort();
    if (nin)
        memcpy(e->ins, ins, (size_t)nin * sizeof *ins);
    if (nout)
        memcpy(e->outs, outs, (size_t)nout * sizeof *outs);
    L->nmemo++;
}

static void lowerer_free(lowerer *L)
{
    for (uint32_t i = 0; i < L->capmemo; i++)
        if (L->memo[i].shader >= 0) {
            free(L->memo[i].ins);
            free(L->memo[i].outs);
        }
    free(L->memo);
    free(L->param_ids);
    free(L->tex_ids);
    sg_map_free(&L->inline_tex);
    for (int i = 0; i < L->ninline_keys; i++)
        free(L->inline_keys[i]);
    free(L->inline_keys);
}

static void lowerer_init(lowerer *L, sg_program *p, ir *ir, sg_diags *d)
{
    memset(L, 0, sizeof *L);
    L->p = p;
    L->ir = ir;
    L->d = d;
    L->tex_ids = xmalloc(((size_t)p->ntextures + 1) * sizeof *L->tex_ids);
    for (int i = 0; i < p->ntextures; i++)
        L->tex_ids[i] = -1;
}

/* ---- values ---------------------------------------------------------------- */

static ir_ref texture_ref(lowerer *L, const sg_texdecl *t)
{
    ir_texture tex = { 0 };
    tex.file = t->file;
    tex.filter = t->filter;
    tex.mip = t->mip;
    tex.wrap = t->wrap;
    tex.srgb = t->srgb;
    tex.lo = 0;
    tex.hi = 1;
    return ir_texture_ref(L->ir, ir_add_texture(L->ir, &tex));
}

/* A string on a texture port: an inline texture with the default sampler
 * state, the file relative to the graph file that names it. */
static ir_ref inline_texture(lowerer *L, const sg_shader *s, const char *file)
{
    char *path = splat_path_join(L->p->files[s->file]->dir, file);
    int idx = sg_map_get(&L->inline_tex, path);
    if (idx >= 0) {
        free(path);
        return ir_texture_ref(L->ir, idx);
    }
    sg_texdecl t = { 0 };
    sg_texdecl_defaults(&t);
    t.file = path;
    ir_ref r = texture_ref(L, &t);
    if (L->ninline_keys == L->capinline_keys) {
        L->capinline_keys = L->capinline_keys ? 2 * L->capinline_keys : 8;
        L->inline_keys = xrealloc(L->inline_keys, (size_t)L->capinline_keys * sizeof *L->inline_keys);
    }
    L->inline_keys[L->ninline_keys++] = path;
    sg_map_put(&L->inline_tex, path, (int)ir_get(L->ir, r)->imm);
    return r;
}

/* `r` converted to type `to`: a float splatted to vecN (constants fold
 * into a vecN constant). */
static ir_ref coerce(lowerer *L, ir_ref r, ir_type to)
{
    ir_type from = ir_typeof(L->ir, r);
    if (from == to || to == IR_T_ERROR || from != IR_T_FLOAT)
        return r;
    const ir_node *n = ir_get(L->ir, r);
    if (n->op == IR_OP_CONST) {
        double v[4] = { n->val[0], n->val[0], n->val[0], n->val[0] };
        return ir_const(L->ir, to, v);
    }
    return ir_splat(L->ir, r, to);
}

typedef struct frame {
    const sg_shader *s;
    const ir_ref    *ins;       /* the shader's inputs                      */
    const ir_ref    *nodes;     /* node outputs, flattened                  */
    const int       *off;       /* first output of node i in `nodes`        */
} frame;

static ir_ref lower_value(lowerer *L, const frame *f, const sg_value *v)
{
    ir_ref r;
    switch (v->kind) {
    case SG_V_NUMBER:
        return ir_constf(L->ir, v->num[0]);
    case SG_V_VEC:
        return ir_const(L->ir, ir_type_vec(v->width), v->num);
    case SG_V_STRING:
        return inline_texture(L, f->s, v->str);
    case SG_V_PATH:
        break;
    default:
        return IR_NONE;
    }
    switch (v->ref) {
    case SG_REF_NODE:    r = f->nodes[f->off[v->node] + v->index]; break;
    case SG_REF_IN:      r = f->ins[v->index]; break;
    case SG_REF_PARAM:   r = ir_param_ref(L->ir, L->param_ids[v->index]); break;
    case SG_REF_INPUT:   r = ir_input(L->ir, (ir_input_kind)v->index); break;
    case SG_REF_VECTOR: {
        /* a painted leaf named vector.NAME[.across] (ir.h) */
        char name[300];
        snprintf(name, sizeof name, "vector.%s%s", v->parts[1], v->index ? ".across" : "");
        r = ir_painted_ref(L->ir, ir_add_painted(L->ir, name));
        break;
    }
    case SG_REF_TEXTURE:
        if (L->tex_ids[v->index] < 0) {
            r = texture_ref(L, L->p->textures[v->index]);
            L->tex_ids[v->index] = (int)ir_get(L->ir, r)->imm;
        } else {
            r = ir_texture_ref(L->ir, L->tex_ids[v->index]);
        }
        break;
    default:
        return IR_NONE;
    }
    if (v->swizzle && ir_ref_ok(r)) {
        if (ir_type_width(ir_typeof(L->ir, r)) == 1) {
            /* float.x / float.xxx: the value itself, splatted */
            int n = (int)strlen(v->swizzle);
            r = n == 1 ? r : ir_splat(L->ir, r, ir_type_vec(n));
        } else {
            r = ir_swizzle(L->ir, r, v->swizzle);
        }
    }
    return r;
}

/* ---- inlining -------------------------------------------------------------- */

static bool inline_shader(lowerer *L, int si, const ir_ref *ins, ir_ref *outs,
                          int depth, sg_loc where);

/* The input values of instance node `n` (callee defaults where unbound). */
static void instance_inputs(lowerer *L, const frame *f, const sg_node *n, ir_ref *cin)
{
    const sg_shader *callee = L->p->shaders[n->shader];
    for (int j = 0; j < callee->nins; j++)
        cin[j] = IR_NONE;
    for (int j = 0; j < n->nargs; j++) {
        const sg_binding *b = &n->args[j];
        cin[b->slot] = coerce(L, lower_value(L, f, &b->val), callee->ins[b->slot].type);
    }
    frame cf = { callee, NULL, NULL, NULL };
    for (int j = 0; j < callee->nins; j++)
        if (!ir_ref_ok(cin[j]))
            cin[j] = coerce(L, lower_value(L, &cf, &callee->ins[j].value), callee->ins[j].type);
}

static bool inline_shader(lowerer *L, int si, const ir_ref *ins, ir_ref *outs,
                          int depth, sg_loc where)
{
    const sg_shader *s = L->p->shaders[si];
    if (depth > SG_MAX_DEPTH) {
        sg_error(L->d, where, SG_E_TOO_DEEP, SG_MAX_DEPTH);
        return false;
    }
    memo_entry *m = memo_find(L, si, ins, s->nins);
    if (m) {
        if (s->nouts)
            memcpy(outs, m->outs, (size_t)s->nouts * sizeof *outs);
        return true;
    }
    int *off = xmalloc(((size_t)s->nnodes + 1) * sizeof *off);
    int total = 0;
    for (int i = 0; i < s->nnodes; i++) {
        off[i] = total;
        const sg_node *n = &s->nodes[i];
        total += n->kind == SG_NODE_INSTANCE ? L->p->shaders[n->shader]->nouts : 1;
    }
    ir_ref *vals = xcalloc((size_t)total + 1, sizeof *vals);
    frame f = { s, ins, vals, off };
    bool ok = true;
    for (int k = 0; k < s->norder && ok; k++) {
        const sg_node *n = &s->nodes[s->order[k]];
        ir_ref *out = &vals[off[s->order[k]]];
        switch (n->kind) {
        case SG_NODE_INPUT:
            if (SG_INPUT_AXIS(n->op) >= 0) {   /* terrain.X.dx / .dy */
                ir_node d = { .op = IR_OP_DINPUT, .type = n->out_type,
                              .imm = IR_DINPUT_IMM(SG_INPUT_OF(n->op), SG_INPUT_AXIS(n->op)) };
                *out = ir_node_add(L->ir, &d);
            } else {
                *out = ir_input(L->ir, (ir_input_kind)n->op);
            }
            break;
        case SG_NODE_PAINTED:
            *out = ir_painted_ref(L->ir, ir_add_painted(L->ir, n->args[0].val.str));
            break;
        case SG_NODE_OP: {
            ir_ref args[4] = { IR_NONE, IR_NONE, IR_NONE, IR_NONE };
            for (int j = 0; j < n->nargs; j++) {
                const sg_binding *b = &n->args[j];
                args[b->slot] = coerce(L, lower_value(L, &f, &b->val), b->splat);
            }
            /* fwidth expands here into its derivatives (ir_footprint):
             * DINPUT leaves, which every stage and the analysis read */
            if (n->op == IR_OP_FWIDTH)
                *out = ir_footprint(L->ir, args[0]);
            else
                *out = ir_opn(L->ir, (ir_op)n->op, args, ir_opinfo_get((ir_op)n->op)->nargs);
            break;
        }
        case SG_NODE_INSTANCE: {
            const sg_shader *callee = L->p->shaders[n->shader];
            ir_ref *cin = xmalloc(((size_t)callee->nins + 1) * sizeof *cin);
            instance_inputs(L, &f, n, cin);
            ok = inline_shader(L, n->shader, cin, out, depth + 1, n->loc);
            free(cin);
            break;
        }
        default:
            ok = false;
            break;
        }
        if (ok && L->ir->nnodes > MAX_IR_NODES) {
            char msg[200];
            snprintf(msg, sizeof msg, "'%s' expands to more than %u IR nodes", s->name,
                     MAX_IR_NODES);
            sg_error(L->d, n->loc, SG_E_OVER_LIMIT, msg);
            ok = false;
        }
    }
    if (ok) {
        for (int i = 0; i < s->nouts; i++) {
            const sg_port *o = &s->outs[i];
            outs[i] = coerce(L, lower_value(L, &f, &o->value), o->type);
        }
        memo_insert(L, si, ins, s->nins, outs, s->nouts);
    }
    free(vals);
    free(off);
    return ok;
}

/* ---- entry points ---------------------------------------------------------- */

static bool program_ok(sg_program *p, sg_diags *d, const char *what, sg_loc loc)
{
    if (p->load_errors == 0)
        return true;
    char msg[300];
    snprintf(msg, sizeof msg, "cannot lower '%s': the program has errors", what);
    sg_error(d, loc, SG_E_HAS_ERRORS, msg);
    return false;
}

bool sg_lower_material(sg_program *p, const char *name, ir *out, sg_diags *d)
{
    sg_loc root = { p->nfiles ? p->files[0]->path : NULL, 0, 0 };
    int mi = sg_material_find(p, name);
    if (mi < 0) {
        sg_error(d, root, SG_E_UNKNOWN_NAME, name);
        return false;
    }
    int si = p->materials[mi];
    const sg_shader *s = p->shaders[si];
    if (!program_ok(p, d, name, s->loc))
        return false;

    lowerer L;
    lowerer_init(&L, p, out, d);
    L.param_ids = xmalloc(((size_t)s->nparams + 1) * sizeof *L.param_ids);
    for (int i = 0; i < s->nparams; i++) {
        const sg_port *pp = &s->params[i];
        size_t n = strlen(name) + strlen(pp->name) + 2;
        char *qname = xmalloc(n);
        snprintf(qname, n, "%s.%s", name, pp->name);
        ir_param param = { .name = qname, .type = pp->type };
        int w = ir_type_width(pp->type);
        for (int c = 0; c < w; c++)
            param.def[c] = pp->value.kind == SG_V_NUMBER ? pp->value.num[0] : pp->value.num[c];
        param.lo = pp->has_range ? pp->lo : param.def[0];
        param.hi = pp->has_range ? pp->hi : param.def[0];
        L.param_ids[i] = ir_add_param(out, &param);
        free(qname);
    }
    ir_ref outs_ref[SG_OUT_COUNT];
    ir_ref *vals = xmalloc(((size_t)s->nouts + 1) * sizeof *vals);
    bool ok = inline_shader(&L, si, NULL, vals, 1, s->loc);
    if (ok) {
        double grey[4] = { 0.5, 0.5, 0.5, 0 };
        outs_ref[SG_OUT_MASK] = ir_constf(out, 1.0);
        outs_ref[SG_OUT_ALBEDO] = ir_const(out, IR_T_VEC3, grey);
        outs_ref[SG_OUT_NORMAL] = ir_input(out, IR_IN_NORMAL);
        outs_ref[SG_OUT_ROUGHNESS] = ir_constf(out, 0.8);
        outs_ref[SG_OUT_HEIGHT] = ir_constf(out, 0.5);
        for (int i = 0; i < s->nouts; i++)
            outs_ref[s->outs[i].output] = vals[i];
        for (int k = 0; k < SG_OUT_COUNT; k++) {
            size_t n = strlen(name) + strlen(sg_output_names[k]) + 2;
            char *rname = xmalloc(n);
            snprintf(rname, n, "%s.%s", name, sg_output_names[k]);
            ir_set_root(out, rname, outs_ref[k]);
            free(rname);
        }
    }
    free(vals);
    lowerer_free(&L);
    return ok;
}

bool sg_lower_shader(sg_program *p, const char *name, ir *out,
                     const char *const *in_names, const ir_ref *in_vals, int nin,
                     const char *const *out_names, ir_ref *out_vals, int nout,
                     sg_diags *d)
{
    sg_loc root = { p->nfiles ? p->files[0]->path : NULL, 0, 0 };
    int si = sg_shader_find(p, name);
    if (si < 0) {
        sg_error(d, root, SG_E_UNKNOWN_NODE, name);
        return false;
    }
    const sg_shader *s = p->shaders[si];
    if (!program_ok(p, d, name, s->loc))
        return false;
    lowerer L;
    lowerer_init(&L, p, out, d);
    ir_ref *ins = calloc((size_t)s->nins + 1, sizeof *ins);
    ir_ref *outs = calloc((size_t)s->nouts + 1, sizeof *outs);
    if (!ins || !outs)
        abort();
    bool ok = true;
    for (int i = 0; i < nin; i++) {
        int k = -1;
        for (int j = 0; j < s->nins; j++)
            if (!strcmp(s->ins[j].name, in_names[i]))
                k = j;
        if (k < 0) {
            sg_error(d, s->loc, SG_E_UNKNOWN_PORT, name, "input", in_names[i]);
            ok = false;
            continue;
        }
        ir_type t = ir_typeof(out, in_vals[i]), want = s->ins[k].type;
        if (t != want && !(t == IR_T_FLOAT && ir_type_width(want) > 1)) {
            char what[200];
            snprintf(what, sizeof what, "input '%s' of '%s'", in_names[i], name);
            sg_error(d, s->ins[k].loc, SG_E_TYPE_MISMATCH, what, ir_type_name(want),
                     ir_type_name(t));
            ok = false;
            continue;
        }
        ins[k] = coerce(&L, in_vals[i], want);
    }
    frame cf = { s, NULL, NULL, NULL };
    for (int j = 0; j < s->nins && ok; j++)
        if (!ir_ref_ok(ins[j])) {
            if (!s->ins[j].has_value) {
                sg_error(d, s->loc, SG_E_MISSING_INPUT, name, s->ins[j].name);
                ok = false;
                continue;
            }
            ins[j] = coerce(&L, lower_value(&L, &cf, &s->ins[j].value), s->ins[j].type);
        }
    int *out_idx = xmalloc(((size_t)nout + 1) * sizeof *out_idx);
    for (int i = 0; i < nout; i++) {
        out_idx[i] = -1;
        for (int j = 0; j < s->nouts; j++)
            if (!strcmp(s->outs[j].name, out_names[i]))
                out_idx[i] = j;
        if (out_idx[i] < 0) {
            sg_error(d, s->loc, SG_E_UNKNOWN_PORT, name, "output", out_names[i]);
            ok = false;
        }
    }
    if (ok)
        ok = inline_shader(&L, si, ins, outs, 1, s->loc);
    for (int i = 0; i < nout && ok; i++)
        out_vals[i] = outs[out_idx[i]];
    free(out_idx);
    free(ins);
    free(outs);
    lowerer_free(&L);
    return ok;
}
