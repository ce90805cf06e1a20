/* resolve_types.c — types of nodes: an op node's result by the op
 * table's rule (the IR builder's, so the two cannot disagree), with a
 * float operand of a componentwise op splatted to the others' width; an
 * instance's bindings against its shader's ports; a painted mask's name.
 *
 * Example: `node r : div { a = n.out, b = d.out }` with both floats is
 * div's rule on (float, float) = float. */
#include "resolve.h"
#include "util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

void rs_check_op(checker *c, sg_node *n)
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
            rs_duplicate(c, b->loc, "port", b->port, slot[k]->loc);
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
    ir_type args[4] = {0}, splat[4] = {0};   /* nargs <= 4 are set */
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
                rs_hint_swizzle(c, &slot[j]->val, cand[k]);
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
bool rs_assignable(const sg_value *v, ir_type want, ir_type *splat)
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

void rs_check_instance(checker *c, sg_node *n)
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
            sg_hint_suggest(c->d, rs_near_port(callee->ins, callee->nins, b->port));
            unknown = true;
            continue;
        }
        if (slot[k]) {
            rs_duplicate(c, b->loc, "port", b->port, slot[k]->loc);
            continue;
        }
        slot[k] = b;
        b->slot = k;
        if (b->val.type == IR_T_ERROR)
            continue;
        if (!rs_assignable(&b->val, callee->ins[k].type, &b->splat)) {
            char what[200];
            snprintf(what, sizeof what, "input '%s' of '%s' (%s)", b->port, n->name, n->type);
            sg_error(c->d, b->val.loc, SG_E_TYPE_MISMATCH, what,
                     ir_type_name(callee->ins[k].type), ir_type_name(b->val.type));
            rs_hint_swizzle(c, &b->val, callee->ins[k].type);
        }
    }
    for (int j = 0; j < callee->nins; j++)
        if (!slot[j] && !callee->ins[j].has_value && !unknown && !n->incomplete)
            sg_error(c->d, n->loc, SG_E_MISSING_INPUT, n->name, callee->ins[j].name);
    free(slot);
}

void rs_check_painted(checker *c, sg_node *n)
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
            rs_duplicate(c, b->loc, "port", b->port, n->args[0].loc);
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
