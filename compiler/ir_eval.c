/* ir_eval.c — the CPU reference: the value of a node in double precision,
 * with the op semantics of the op table (ir_ops.c).  The DAG is evaluated
 * with memoisation: each node reachable from `r` is computed once, in id
 * order (ids are topological).  The leaves read the environment: terrain
 * inputs, params (NULL: their defaults), painted masks (NULL: 0) and
 * texture samples (NULL sampler: every texture reads (0.5, 0.5, 0.5, 1)).
 */
#include "ir.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

/* An input's value: its ir_env slot (IR_INPUTS' ev column). */
static void eval_input(const ir_env *env, uint32_t which, double *out)
{
    assert(which < IR_IN_COUNT);
    const ir_input_info *in = ir_input_get((ir_input_kind)which);
    const double *v = (const double *)((const char *)env + in->env_off);
    memcpy(out, v, (size_t)ir_type_width(in->type) * sizeof *v);
    if (which == IR_IN_VIEW_DIRECTION && out[0] == 0.0 && out[1] == 0.0 && out[2] == 0.0)
        out[1] = 1.0;                 /* unset: looking straight down */
}

void ir_eval_node(const ir *ir, uint32_t id, const ir_env *env, double (*vals)[4])
{
    const ir_node *n = &ir->nodes[id];
    double *out = vals[id];
    memset(out, 0, 4 * sizeof(double));
    switch (n->op) {
    case IR_OP_CONST:
        memcpy(out, n->val, sizeof n->val);
        return;
    case IR_OP_INPUT:
        eval_input(env, n->imm, out);
        return;
    case IR_OP_PARAM:
        memcpy(out, env->params ? env->params + 4 * n->imm : ir->params[n->imm].def,
               4 * sizeof(double));
        return;
    case IR_OP_TEXTURE:
        out[0] = n->imm;          /* a handle: its index, for SAMPLE */
        return;
    case IR_OP_PAINTED:
        out[0] = env->painted ? env->painted[n->imm] : 0.0;
        return;
    case IR_OP_DINPUT:
        memcpy(out, env->d_input[IR_DINPUT_AXIS(n->imm)][IR_DINPUT_INPUT(n->imm)],
               4 * sizeof(double));
        return;
    case IR_OP_SAMPLE:        /* the gradients do not change level 0 */
    case IR_OP_SAMPLE_GRAD: {
        const double *uv = vals[n->arg[1].id];
        int tex = (int)ir->nodes[n->arg[0].id].imm;
        if (env->sample_grad && n->op == IR_OP_SAMPLE_GRAD) {
            env->sample_grad(env->sample_user, tex, uv, vals[n->arg[2].id],
                             vals[n->arg[3].id], out);
        } else if (env->sample) {
            env->sample(env->sample_user, tex, uv[0], uv[1], out);
        } else {
            out[0] = out[1] = out[2] = 0.5;
            out[3] = 1.0;
        }
        return;
    }
    default: {
        const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
        double a[16];
        ir_type at[4];
        for (int i = 0; i < n->nargs; i++) {
            memcpy(&a[4 * i], vals[n->arg[i].id], 4 * sizeof(double));
            at[i] = (ir_type)ir->nodes[n->arg[i].id].type;
        }
        assert(info->eval);
        info->eval(n, at, a, out);
        return;
    }
    }
}

void ir_eval(const ir *ir, ir_ref r, const ir_env *env, double out[4])
{
    static const ir_env zero_env;
    if (!env)
        env = &zero_env;
    memset(out, 0, 4 * sizeof(double));
    if (!ir_ref_ok(r))
        return;
    assert(r.id < ir->nnodes);
    double (*vals)[4] = malloc(sizeof(double[4]) * (r.id + 1));
    uint8_t *need = calloc(r.id + 1, 1);
    if (!vals || !need) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    /* Operands have smaller ids: mark downwards, evaluate upwards. */
    need[r.id] = 1;
    for (uint32_t id = r.id; id > 0; id--)
        if (need[id])
            for (int i = 0; i < ir->nodes[id].nargs; i++)
                need[ir->nodes[id].arg[i].id] = 1;
    for (uint32_t id = 1; id <= r.id; id++)
        if (need[id])
            ir_eval_node(ir, id, env, vals);
    memcpy(out, vals[r.id], 4 * sizeof(double));
    free(vals);
    free(need);
}
