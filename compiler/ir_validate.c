/* ir_validate.c — the IR's invariants, checked after every pass in debug
 * builds (ir_optimize with SPLAT_VALIDATE_IR) and by the unit tests.
 *
 * Checked: node 0 is the empty "none" node; every operand id is in range
 * and smaller than its user's (topological order); arities; every node's
 * type is what its op's type rule gives (leaves: the input's / param's
 * type, handles for textures); swizzle immediates in range; commutative
 * operands in canonical order; unused operand slots and constant
 * components zero; table indices in range; the hash-cons table holds
 * exactly the nodes and no two nodes are equal; roots in range with
 * distinct names.  Each failure prints "file:line: #cond (node N)".
 */
#include "ir.h"

#include <stdlib.h>
#include <string.h>

typedef struct vstate {
    FILE    *out;
    uint32_t node;      /* node being checked, 0 for whole-IR checks */
    int      failures;
} vstate;

static void fail(vstate *st, const char *cond, const char *file, int line)
{
    st->failures++;
    if (st->out)
        fprintf(st->out, "%s:%d: %s (node %u)\n", file, line, cond, st->node);
}

#define VALIDATE(st, cond)                                  \
    do {                                                    \
        if (!(cond))                                        \
            fail((st), #cond, __FILE__, __LINE__);          \
    } while (0)

static void validate_leaf(vstate *st, const ir *ir, const ir_node *n)
{
    ir_type t = (ir_type)n->type;
    switch (n->op) {
    case IR_OP_CONST:
        VALIDATE(st, ir_type_width(t) > 0);
        for (int c = ir_type_width(t); c < 4 && ir_type_width(t) > 0; c++)
            VALIDATE(st, n->val[c] == 0.0);
        break;
    case IR_OP_INPUT:
        VALIDATE(st, n->imm < IR_IN_COUNT);
        if (n->imm < IR_IN_COUNT)
            VALIDATE(st, t == ir_input_get((ir_input_kind)n->imm)->type);
        break;
    case IR_OP_PARAM:
        VALIDATE(st, (int)n->imm < ir->nparams);
        if ((int)n->imm < ir->nparams)
            VALIDATE(st, t == ir->params[n->imm].type);
        break;
    case IR_OP_TEXTURE:
        VALIDATE(st, (int)n->imm < ir->ntextures);
        VALIDATE(st, t == IR_T_TEX);
        break;
    case IR_OP_PAINTED:
        VALIDATE(st, (int)n->imm < ir->npainted);
        VALIDATE(st, t == IR_T_FLOAT);
        break;
    case IR_OP_DINPUT: {
        int in = IR_DINPUT_INPUT(n->imm);
        VALIDATE(st, in < IR_IN_COUNT && IR_DINPUT_AXIS(n->imm) < 2 &&
                     (n->imm >> 16) <= 1);
        if (in < IR_IN_COUNT)
            VALIDATE(st, t == ir_input_get((ir_input_kind)in)->type);
        break;
    }
    }
}

static void validate_op(vstate *st, const ir *ir, uint32_t id, const ir_node *n)
{
    const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
    if (n->op == IR_OP_CONSTRUCT)
        VALIDATE(st, n->nargs >= 1 && n->nargs <= 4);
    else
        VALIDATE(st, n->nargs == info->nargs);
    ir_type at[4];
    for (int i = 0; i < n->nargs && i < 4; i++) {
        VALIDATE(st, n->arg[i].id > 0 && n->arg[i].id < id);
        if (n->arg[i].id == 0 || n->arg[i].id >= id)
            return;
        at[i] = ir_typeof(ir, n->arg[i]);
    }
    ir_type rule = info->type(at, n->nargs);
    VALIDATE(st, rule != IR_T_ERROR);
    switch (n->op) {
    case IR_OP_SPLAT:
        VALIDATE(st, ir_type_width((ir_type)n->type) >= 2);
        break;
    case IR_OP_SWIZZLE: {
        int w = IR_SWZ_N(n->imm);
        VALIDATE(st, w >= 1 && w <= 4);
        VALIDATE(st, n->type == ir_type_vec(w));
        for (int i = 0; i < w && i < 4; i++)
            VALIDATE(st, IR_SWZ_C(n->imm, i) < ir_type_width(at[0]));
        VALIDATE(st, (n->imm >> (4 + 2 * w)) == 0);
        break;
    }
    default:
        VALIDATE(st, n->type == rule);
        VALIDATE(st, n->imm == 0);
        break;
    }
    if (info->flags & IR_COMMUTATIVE)
        VALIDATE(st, n->arg[0].id <= n->arg[1].id);
    if (n->op == IR_OP_SAMPLE || n->op == IR_OP_SAMPLE_GRAD)
        VALIDATE(st, ir_get(ir, n->arg[0])->op == IR_OP_TEXTURE);
    for (int c = 0; c < 4; c++)
        VALIDATE(st, n->val[c] == 0.0);
}

static int cmp_name(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

bool ir_validate(const ir *ir, FILE *out)
{
    vstate st = {out, 0, 0};
    VALIDATE(&st, ir->nnodes >= 1 && ir->nnodes <= ir->capnodes);
    VALIDATE(&st, ir->nodes[0].op == IR_OP_CONST && ir->nodes[0].type == IR_T_ERROR);
    VALIDATE(&st, ir->captable >= 2 * ir->nnodes - 1 &&
                  (ir->captable & (ir->captable - 1)) == 0);

    for (uint32_t id = 1; id < ir->nnodes; id++) {
        const ir_node *n = &ir->nodes[id];
        st.node = id;
        VALIDATE(&st, n->op < IR_OP_COUNT);
        if (n->op >= IR_OP_COUNT)
            continue;
        VALIDATE(&st, n->pad == 0);
        for (int i = n->nargs; i < 4; i++)
            VALIDATE(&st, n->arg[i].id == 0);
        if (n->op <= IR_OP_PAINTED || n->op == IR_OP_DINPUT) {
            VALIDATE(&st, n->nargs == 0);
            validate_leaf(&st, ir, n);
        } else {
            validate_op(&st, ir, id, n);
        }
        /* hash-consed: the table finds this very node (so no equal twin) */
        VALIDATE(&st, ir_lookup(ir, n).id == id);
    }

    st.node = 0;
    uint32_t filled = 0;
    for (uint32_t i = 0; i < ir->captable; i++) {
        if (!ir->table[i])
            continue;
        filled++;
        VALIDATE(&st, ir->table[i] < ir->nnodes);
    }
    VALIDATE(&st, filled == ir->nnodes - 1);

    /* root names unique: sorted, then neighbours compared (the validator
     * runs after every pass, and the über-shader has a root per material
     * output: pairwise it was a tenth of a one-material rebuild) */
    const char **names = ir->nroots ? malloc((size_t)ir->nroots * sizeof *names) : NULL;
    int nnames = 0;
    for (int i = 0; i < ir->nroots; i++) {
        VALIDATE(&st, ir->roots[i].name != NULL);
        VALIDATE(&st, ir->roots[i].ref.id < ir->nnodes);
        if (names && ir->roots[i].name)
            names[nnames++] = ir->roots[i].name;
    }
    if (names) {
        qsort(names, (size_t)nnames, sizeof *names, cmp_name);
        for (int i = 1; i < nnames; i++)
            VALIDATE(&st, strcmp(names[i], names[i - 1]) != 0);
        free(names);
    } else {
        for (int i = 0; i < ir->nroots; i++)   /* no memory: pairwise */
            for (int j = 0; j < i; j++)
                VALIDATE(&st, !ir->roots[i].name || !ir->roots[j].name ||
                                  strcmp(ir->roots[i].name, ir->roots[j].name) != 0);
    }
    for (int i = 0; i < ir->nparams; i++) {
        VALIDATE(&st, ir->params[i].name != NULL);
        VALIDATE(&st, ir_type_width(ir->params[i].type) > 0);
    }
    for (int i = 0; i < ir->ntextures; i++)
        VALIDATE(&st, ir->textures[i].file != NULL && ir->textures[i].lo <= ir->textures[i].hi);
    return st.failures == 0;
}
