/* ir_interval.c — sound bounds of a node's value over a region of inputs.
 *
 * For every input point inside the region (ir_ienv), the value ir_eval
 * computes lies inside the bounds returned here, component by component.
 * The per-op rules live beside the values in the op table (ir_ops.c:
 * endpoints for monotone ops, critical points for the others, outward
 * widening where rounding could break soundness, [-inf, +inf] wherever a
 * NaN is possible).  This file evaluates the DAG once per node and
 * supplies the leaves: inputs from the region, params from env->params or
 * their declared [lo, hi] (their default if fixed), painted masks from
 * env->painted or [0, 1], and SAMPLE from its texture's [lo, hi].
 */
#include "ir.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* An input's bounds: its ir_ienv slot, or its domain where it has none
 * (IR_INPUTS' iv and domain columns: view.direction, any camera). */
static void input_bounds(const ir_ienv *env, uint32_t which, ir_iv *out)
{
    assert(which < IR_IN_COUNT);
    const ir_input_info *in = ir_input_get((ir_input_kind)which);
    int w = ir_type_width(in->type);
    if (in->ienv_off < 0)
        memcpy(out, in->domain, (size_t)w * sizeof *out);
    else
        memcpy(out, (const char *)env + in->ienv_off, (size_t)w * sizeof *out);
}

static void param_bounds(const ir *ir, const ir_ienv *env, uint32_t i, ir_iv *out)
{
    const ir_param *p = &ir->params[i];
    int w = ir_type_width(p->type);
    for (int c = 0; c < w; c++) {
        if (env->params)
            out[c] = env->params[i];
        else if (p->lo == p->hi)
            out[c] = (ir_iv){p->def[c], p->def[c]};   /* fixed: the default */
        else
            out[c] = (ir_iv){p->lo, p->hi};
    }
}

static void bound_node(const ir *ir, uint32_t id, const ir_ienv *env, ir_iv (*vals)[4])
{
    const ir_node *n = &ir->nodes[id];
    ir_iv *out = vals[id];
    for (int c = 0; c < 4; c++)
        out[c] = (ir_iv){0, 0};
    switch (n->op) {
    case IR_OP_CONST:
        for (int c = 0; c < 4; c++)
            out[c] = isnan(n->val[c]) ? (ir_iv){-INFINITY, INFINITY}
                                      : (ir_iv){n->val[c], n->val[c]};
        return;
    case IR_OP_INPUT:
        input_bounds(env, n->imm, out);
        return;
    case IR_OP_PARAM:
        param_bounds(ir, env, n->imm, out);
        return;
    case IR_OP_TEXTURE:
        return;
    case IR_OP_PAINTED:
        out[0] = env->painted ? env->painted[n->imm] : (ir_iv){0, 1};
        return;
    case IR_OP_DINPUT:        /* unbounded: the region has no derivatives */
        for (int c = 0; c < 4; c++)
            out[c] = (ir_iv){-INFINITY, INFINITY};
        return;
    case IR_OP_SAMPLE:
    case IR_OP_SAMPLE_GRAD: {
        const ir_texture *t = &ir->textures[ir->nodes[n->arg[0].id].imm];
        for (int c = 0; c < 4; c++)
            out[c] = (ir_iv){t->lo, t->hi};
        return;
    }
    default: {
        const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
        ir_iv a[16];
        ir_type at[4];
        for (int i = 0; i < n->nargs; i++) {
            memcpy(&a[4 * i], vals[n->arg[i].id], 4 * sizeof(ir_iv));
            at[i] = (ir_type)ir->nodes[n->arg[i].id].type;
        }
        assert(info->interval);
        info->interval(n, at, a, out);
        return;
    }
    }
}

void ir_interval(const ir *ir, ir_ref r, const ir_ienv *env, ir_iv out[4])
{
    for (int c = 0; c < 4; c++)
        out[c] = (ir_iv){0, 0};
    if (!ir_ref_ok(r))
        return;
    assert(r.id < ir->nnodes && env);
    ir_iv (*vals)[4] = malloc(sizeof(ir_iv[4]) * (r.id + 1));
    uint8_t *need = calloc(r.id + 1, 1);
    if (!vals || !need) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    need[r.id] = 1;
    for (uint32_t id = r.id; id > 0; id--)
        if (need[id])
            for (int i = 0; i < ir->nodes[id].nargs; i++)
                need[ir->nodes[id].arg[i].id] = 1;
    for (uint32_t id = 1; id <= r.id; id++)
        if (need[id])
            bound_node(ir, id, env, vals);
    memcpy(out, vals[r.id], 4 * sizeof(ir_iv));
    free(vals);
    free(need);
}

void ir_interval_nodes(const ir *ir, const ir_ienv *env, ir_iv (*vals)[4])
{
    assert(env);
    for (int c = 0; c < 4; c++)
        vals[0][c] = (ir_iv){0, 0};
    for (uint32_t id = 1; id < ir->nnodes; id++)
        bound_node(ir, id, env, vals);
}
