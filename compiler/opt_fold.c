/* opt_fold.c — constant folding and safe algebraic identities.
 *
 * Rebuilds the IR bottom-up (ir_rebuild), replacing each node:
 *   - an op whose operands are all constants by the constant the op
 *     table's eval computes (the same function as ir_eval, so folding can
 *     never change a value) — unless the result is not a finite float, which
 *     stays an expression so the GPU computes it its own way;
 *   - x + 0, x - 0, x * 1, x / 1, min(x, x), max(x, x), -(-x) by x
 *     (and x - x by 0 where x is provably finite, below)
 *     (exact for every x, NaN and inf included; x + 0 turns -0 into +0,
 *     which no output can tell apart);
 *   - x * 0 by 0 only where x is provably finite (a NaN or inf x would
 *     give NaN): the op table's finiteness column (IR_FIN_*) says which —
 *     saturate/step/smoothstep/less results, clamps with finite bounds,
 *     inputs, painted masks, params with a finite range, texture samples
 *     of a finite range, and finite constants.  Everything else keeps it;
 *   - saturate(saturate(x)) by saturate(x); select(c, a, b) with a
 *     constant c by a or b, select(c, x, x) by x; mix(x, x, t) by x where
 *     t is view.shading_lod, which is exactly 0 or 1 (the CPU shading
 *     LOD's switch: a distance class that pins a node's full side to its
 *     LOD side, as parallax's uv beyond its fade, then reads x itself, as
 *     it did before the switch, and the driver folds the mix the same way
 *     once the constant is known);
 *   - splat of a constant by a vector constant; swizzle of a constant, of
 *     a splat, of a swizzle, and of a construct whose picked components
 *     are all floats, by the picked values.
 *
 * Before:                                  After:
 *   node n1 : terrain.height                 node n1 : terrain.height
 *   node n4 : mul { a = n1.out, b = 1.0 }    node n3 : add { a = n1.out, b = 2.5 }
 *   node n5 : add { a = 2.0, b = 0.5 }       out m.mask = n3.out
 *   node n6 : add { a = n4.out, b = n5.out }
 *   out m.mask = n6.out
 */
#include "ir.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <string.h>

static const ir_node *N(const ir *ir, ir_ref r) { return ir_get(ir, r); }

static bool is_const(const ir *ir, ir_ref r) { return N(ir, r)->op == IR_OP_CONST; }

/* A constant whose every component equals v. */
static bool is_const_all(const ir *ir, ir_ref r, double v)
{
    const ir_node *n = N(ir, r);
    if (n->op != IR_OP_CONST)
        return false;
    for (int c = 0; c < ir_type_width((ir_type)n->type); c++)
        if (n->val[c] != v)
            return false;
    return true;
}

static bool finite_iv(double lo, double hi) { return isfinite(lo) && isfinite(hi); }

/* Conservative: true only where the value can be neither NaN nor inf.
 * The op table's finiteness column says when (IR_FIN_*); only the leaves
 * whose data decides (IR_FIN_DATA) are looked at here. */
static bool provably_finite(const ir *ir, ir_ref r)
{
    const ir_node *n = N(ir, r);
    unsigned fin = ir_opinfo_get((ir_op)n->op)->finite;
    if (fin & IR_FIN_ARGS_BIT) {
        for (int i = 0; i < n->nargs; i++)
            if ((fin >> i & 1) && !provably_finite(ir, n->arg[i]))
                return false;
        return true;
    }
    if (fin != IR_FIN_DATA)
        return fin == IR_FIN_YES;
    switch (n->op) {
    case IR_OP_CONST:
        for (int c = 0; c < 4; c++)
            if (!isfinite(n->val[c]))
                return false;
        return true;
    case IR_OP_PARAM: {
        const ir_param *p = &ir->params[n->imm];
        return finite_iv(p->lo, p->hi) && finite_iv(p->def[0], p->def[3]) &&
               finite_iv(p->def[1], p->def[2]);
    }
    case IR_OP_SAMPLE:
    case IR_OP_SAMPLE_GRAD: {
        const ir_texture *t = &ir->textures[N(ir, n->arg[0])->imm];
        return finite_iv(t->lo, t->hi);
    }
    default:
        assert(!"IR_FIN_DATA for an op whose data is not looked at");
        return false;
    }
}

/* All-constant operands: evaluate with the op table. */
static ir_ref fold_const(ir *dst, const ir_node *n)
{
    const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
    if (!info->eval || n->nargs == 0)
        return IR_NONE;
    double a[16] = {0}, out[4] = {0};
    ir_type at[4];
    for (int i = 0; i < n->nargs; i++) {
        const ir_node *arg = N(dst, n->arg[i]);
        if (arg->op != IR_OP_CONST)
            return IR_NONE;
        memcpy(&a[4 * i], arg->val, sizeof arg->val);
        at[i] = (ir_type)arg->type;
    }
    info->eval(n, at, a, out);
    for (int c = 0; c < ir_type_width((ir_type)n->type); c++)
        if (!isfinite(out[c]) || fabs(out[c]) > FLT_MAX)
            return IR_NONE;
    return ir_const(dst, (ir_type)n->type, out);
}

static ir_ref fold_swizzle(ir *dst, const ir_node *n)
{
    const ir_node *a = N(dst, n->arg[0]);
    int w = IR_SWZ_N(n->imm);
    ir_type t = (ir_type)n->type;
    switch (a->op) {
    case IR_OP_SPLAT:                       /* splat(f).xy = splat(f) */
        return w == 1 ? a->arg[0] : ir_splat(dst, a->arg[0], t);
    case IR_OP_SWIZZLE: {                   /* v.zyx.xy = v.zy */
        const char *xyzw = "xyzw";
        char comps[5] = {0};
        for (int i = 0; i < w; i++)
            comps[i] = xyzw[IR_SWZ_C(a->imm, IR_SWZ_C(n->imm, i))];
        return ir_swizzle(dst, a->arg[0], comps);
    }
    case IR_OP_CONSTRUCT: {                 /* vec3(a, b, c).zx = vec2(c, a) */
        ir_ref pick[4];
        for (int i = 0; i < w; i++) {
            int comp = IR_SWZ_C(n->imm, i), k = 0;
            for (int j = 0; j < a->nargs; j++) {
                int aw = ir_type_width(ir_typeof(dst, a->arg[j]));
                if (comp < k + aw) {
                    if (aw != 1)
                        return IR_NONE;     /* would need a new swizzle */
                    pick[i] = a->arg[j];
                    break;
                }
                k += aw;
            }
        }
        return w == 1 ? pick[0] : ir_construct(dst, t, pick, w);
    }
    default:
        return IR_NONE;
    }
}

static ir_ref fold_identity(ir *dst, const ir_node *n)
{
    ir_ref a = n->arg[0], b = n->arg[1];
    switch (n->op) {
    case IR_OP_ADD:
        if (is_const_all(dst, b, 0.0)) return a;
        if (is_const_all(dst, a, 0.0)) return b;
        return IR_NONE;
    case IR_OP_SUB:
        if (is_const_all(dst, b, 0.0)) return a;
        if (ir_ref_eq(a, b) && provably_finite(dst, a)) {   /* x - x: 0 unless inf/NaN */
            double zero[4] = {0};
            return ir_const(dst, (ir_type)n->type, zero);
        }
        return IR_NONE;
    case IR_OP_MUL:
        if (is_const_all(dst, b, 1.0)) return a;
        if (is_const_all(dst, a, 1.0)) return b;
        if (is_const_all(dst, a, 0.0) && provably_finite(dst, b)) return a;
        if (is_const_all(dst, b, 0.0) && provably_finite(dst, a)) return b;
        return IR_NONE;
    case IR_OP_DIV:
        return is_const_all(dst, b, 1.0) ? a : IR_NONE;
    case IR_OP_MIN:
    case IR_OP_MAX:
        return ir_ref_eq(a, b) ? a : IR_NONE;
    case IR_OP_NEG:
        return N(dst, a)->op == IR_OP_NEG ? N(dst, a)->arg[0] : IR_NONE;
    case IR_OP_SATURATE:
        return N(dst, a)->op == IR_OP_SATURATE ? a : IR_NONE;
    case IR_OP_MIX: {   /* mix(x, x, view.shading_lod): x */
        const ir_node *t = N(dst, n->arg[2]);
        if (t->op == IR_OP_SPLAT)
            t = N(dst, t->arg[0]);
        return ir_ref_eq(a, b) && t->op == IR_OP_INPUT && t->imm == IR_IN_SHADING_LOD
                   ? a : IR_NONE;
    }
    case IR_OP_SELECT: {
        if (ir_ref_eq(n->arg[1], n->arg[2]))   /* select(c, x, x): x */
            return n->arg[1];
        if (!is_const(dst, a))
            return IR_NONE;
        const ir_node *c = N(dst, a);
        bool all_true = true, all_false = true;
        for (int i = 0; i < ir_type_width((ir_type)c->type); i++) {
            all_true = all_true && c->val[i] != 0;     /* NaN counts as true */
            all_false = all_false && c->val[i] == 0;
        }
        return all_true ? n->arg[1] : all_false ? n->arg[2] : IR_NONE;
    }
    case IR_OP_SWIZZLE:
        return fold_swizzle(dst, n);
    default:
        return IR_NONE;
    }
}

static ir_ref fold(ir *dst, const ir_node *n, void *user)
{
    ir_ref r = fold_const(dst, n);
    if (!ir_ref_ok(r))
        r = fold_identity(dst, n);
    return ir_ref_ok(r) ? r : ir_node_add(dst, n);
}

bool opt_fold(ir *ir)
{
    return ir_rebuild(ir, fold, NULL);
}
