/* ir_derive_rules.c — the op table's derivative column (IR_OPS' deriv,
 * ir.h): each op's forward-mode derivative rule, and the arithmetic on
 * derivatives the rules and the pass build with (IR_NONE reads as zero).
 * ir_differentiate.c walks the IR and asks ir_deriv_rule(op) for a node's
 * rule.  The rules sit below the pass: they build with ir.c's builders and
 * read the op and input tables (ir_ops.c), and call nothing above.
 *
 * Example: mul(a, b) with derivatives da, db becomes
 *     add(mul(da, b), mul(a, db))      (a zero side is never built)
 */
#include "ir.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>

/* ---- arithmetic on derivatives (IR_NONE is zero) ------------------------ */

/* a float operand next to a vector one is splatted to its width */
static void widen(ir_dctx *c, ir_ref *a, ir_ref *b)
{
    ir_type ta = ir_typeof(c->ir, *a), tb = ir_typeof(c->ir, *b);
    if (ta == IR_T_FLOAT && tb != IR_T_FLOAT)
        *a = ir_splat(c->ir, *a, tb);
    else if (tb == IR_T_FLOAT && ta != IR_T_FLOAT)
        *b = ir_splat(c->ir, *b, ta);
}

ir_ref ir_d_add(ir_dctx *c, ir_ref a, ir_ref b)
{
    if (!ir_ref_ok(a))
        return b;
    if (!ir_ref_ok(b))
        return a;
    widen(c, &a, &b);
    return ir_op2(c->ir, IR_OP_ADD, a, b);
}

ir_ref ir_d_sub(ir_dctx *c, ir_ref a, ir_ref b)
{
    if (!ir_ref_ok(b))
        return a;
    if (!ir_ref_ok(a))
        return ir_op1(c->ir, IR_OP_NEG, b);
    widen(c, &a, &b);
    return ir_op2(c->ir, IR_OP_SUB, a, b);
}

ir_ref ir_d_mul(ir_dctx *c, ir_ref a, ir_ref b)
{
    if (!ir_ref_ok(a) || !ir_ref_ok(b))
        return IR_NONE;
    widen(c, &a, &b);
    return ir_op2(c->ir, IR_OP_MUL, a, b);
}

ir_ref ir_d_div(ir_dctx *c, ir_ref a, ir_ref b)
{
    if (!ir_ref_ok(a))
        return IR_NONE;
    widen(c, &a, &b);
    return ir_op2(c->ir, IR_OP_DIV, a, b);
}

ir_ref ir_d_num(ir_dctx *c, ir_type t, double v)
{
    double vals[4] = {v, v, v, v};
    return ir_const(c->ir, t, vals);
}

ir_ref ir_d_zero(ir_dctx *c, ir_ref d, ir_type t)
{
    return ir_ref_ok(d) ? d : ir_d_num(c, t, 0.0);
}

/* ---- the rules ---------------------------------------------------------- */

/* Each returns the derivative of `self` (= *n) along c->axis from its
 * operands n->arg[i] and their derivatives d[i] (IR_NONE = 0), or IR_NONE.
 * They follow the double semantics above: min/max/abs/clamp/saturate take
 * the derivative of the operand they return, step/less/floor are 0, a
 * select differentiates the side it takes. */

#define A(i) (n->arg[i])
#define T    ((ir_type)n->type)

/* An input moves where its row has a derivative accessor (IR_INPUTS'
 * dglsl column); destruction is taken as 0, and so are normal and slope
 * unless a footprint asks (c->curvature: texture gradients never do). */
static ir_ref d_input(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    if (!ir_input_get((ir_input_kind)n->imm)->dglsl)
        return IR_NONE;
    if (!c->curvature && (n->imm == IR_IN_SLOPE || n->imm == IR_IN_NORMAL))
        return IR_NONE;
    /* a footprint's leaves are marked (the CPU shading LOD's, ir.h) */
    uint32_t fp = c->curvature ? IR_DINPUT_FOOTPRINT : 0;
    if (n->imm == IR_IN_SLOPE) {   /* 1 - normal.y: one normal step for both */
        ir_node l = {.op = IR_OP_DINPUT, .type = IR_T_VEC3,
                     .imm = IR_DINPUT_IMM(IR_IN_NORMAL, c->axis) | fp};
        return ir_op1(c->ir, IR_OP_NEG, ir_swizzle(c->ir, ir_node_add(c->ir, &l), "y"));
    }
    ir_node l = {.op = IR_OP_DINPUT, .type = n->type,
                 .imm = IR_DINPUT_IMM(n->imm, c->axis) | fp};
    return ir_node_add(c->ir, &l);
}

/* The op itself over the derivatives (linear ops: splat, swizzle,
 * construct, neg; zeros written out where some operand moves). */
static ir_ref d_linear(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_node m = *n;
    for (int i = 0; i < n->nargs; i++)
        m.arg[i] = ir_d_zero(c, d[i], ir_typeof(c->ir, n->arg[i]));
    return ir_node_add(c->ir, &m);
}

static ir_ref d_add(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return ir_d_add(c, d[0], d[1]);
}

static ir_ref d_sub(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return ir_d_sub(c, d[0], d[1]);
}

static ir_ref d_mul(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return ir_d_add(c, ir_d_mul(c, d[0], A(1)), ir_d_mul(c, A(0), d[1]));
}

/* (a / b)' = (a' - q b') / b */
static ir_ref d_div(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return ir_d_div(c, ir_d_sub(c, d[0], ir_d_mul(c, self, d[1])), A(1));
}

/* select(cond, a', b') with zeros written out; NONE if both are zero */
static ir_ref pick(ir_dctx *c, ir_ref cond, ir_ref da, ir_ref db, ir_type t)
{
    if (!ir_ref_ok(da) && !ir_ref_ok(db))
        return IR_NONE;
    return ir_op3(c->ir, IR_OP_SELECT, cond, ir_d_zero(c, da, t), ir_d_zero(c, db, t));
}

/* fmin(a, b) is a where a < b, else b; fmax(a, b) a where b < a */
static ir_ref min_rule(ir_dctx *c, ir_ref a, ir_ref b, ir_ref da, ir_ref db, ir_type t)
{
    return pick(c, ir_op2(c->ir, IR_OP_LESS, a, b), da, db, t);
}

static ir_ref max_rule(ir_dctx *c, ir_ref a, ir_ref b, ir_ref da, ir_ref db, ir_type t)
{
    return pick(c, ir_op2(c->ir, IR_OP_LESS, b, a), da, db, t);
}

static ir_ref d_min(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return min_rule(c, A(0), A(1), d[0], d[1], T);
}

static ir_ref d_max(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return max_rule(c, A(0), A(1), d[0], d[1], T);
}

static ir_ref d_abs(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref neg = ir_op2(c->ir, IR_OP_LESS, A(0), ir_d_num(c, T, 0.0));
    return pick(c, neg, ir_op1(c->ir, IR_OP_NEG, d[0]), d[0], T);
}

static ir_ref d_fract(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return d[0];
}

/* mod(x, y) = x - y floor(x / y) */
static ir_ref d_mod(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref k = ir_op1(c->ir, IR_OP_FLOOR, ir_op2(c->ir, IR_OP_DIV, A(0), A(1)));
    return ir_d_sub(c, d[0], ir_d_mul(c, k, d[1]));
}

/* `e` where the operand's derivative d is not 0, else 0: for rules whose
 * partial is infinite where it does not move (sqrt(0), pow(0, 0.5)'s,
 * log2(0), length(0)): a clamped sqrt(saturate(x)) must read 0, not 0 * inf. */
static ir_ref guarded(ir_dctx *c, ir_ref cond, ir_ref e)
{
    if (!ir_ref_ok(e))
        return e;
    ir_type t = ir_typeof(c->ir, e);
    if (ir_typeof(c->ir, cond) != t)
        cond = ir_splat(c->ir, cond, t);
    return ir_op3(c->ir, IR_OP_SELECT, cond, e, ir_d_num(c, t, 0.0));
}

static ir_ref d_sqrt(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return guarded(c, d[0], ir_d_div(c, ir_d_mul(c, d[0], ir_d_num(c, T, 0.5)), self));
}

/* pow(x, y)' = y pow(x, y - 1) x' + pow(x, y) ln(x) y' */
static ir_ref d_pow(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref dx = IR_NONE, dy = IR_NONE;
    if (ir_ref_ok(d[0])) {
        ir_ref ym1 = ir_op2(c->ir, IR_OP_SUB, A(1), ir_d_num(c, T, 1.0));
        ir_ref k = ir_op2(c->ir, IR_OP_MUL, A(1), ir_op2(c->ir, IR_OP_POW, A(0), ym1));
        dx = guarded(c, d[0], ir_d_mul(c, k, d[0]));
    }
    if (ir_ref_ok(d[1])) {
        ir_ref ln = ir_op2(c->ir, IR_OP_MUL, ir_op1(c->ir, IR_OP_LOG2, A(0)),
                           ir_d_num(c, T, M_LN2));
        /* 0 where the power is 0 (x = 0: 0 * ln 0) */
        dy = guarded(c, self, guarded(c, d[1], ir_d_mul(c, ir_op2(c->ir, IR_OP_MUL, self, ln),
                                                        d[1])));
    }
    return ir_d_add(c, dx, dy);
}

static ir_ref d_exp2(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return ir_d_mul(c, ir_op2(c->ir, IR_OP_MUL, self, ir_d_num(c, T, M_LN2)), d[0]);
}

static ir_ref d_log2(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return guarded(c, d[0],
                   ir_d_div(c, d[0], ir_op2(c->ir, IR_OP_MUL, A(0), ir_d_num(c, T, M_LN2))));
}

static ir_ref d_sin(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return ir_d_mul(c, ir_op1(c->ir, IR_OP_COS, A(0)), d[0]);
}

static ir_ref d_cos(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return ir_d_mul(c, ir_op1(c->ir, IR_OP_NEG, ir_op1(c->ir, IR_OP_SIN, A(0))), d[0]);
}

/* mix(a, b, t)' = mix(a', b', t) + (b - a) t' */
static ir_ref d_mix(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref ab = IR_NONE;
    if (ir_ref_ok(d[0]) || ir_ref_ok(d[1]))
        ab = ir_op3(c->ir, IR_OP_MIX, ir_d_zero(c, d[0], T), ir_d_zero(c, d[1], T), A(2));
    return ir_d_add(c, ab, ir_d_mul(c, ir_op2(c->ir, IR_OP_SUB, A(1), A(0)), d[2]));
}

/* clamp(x, lo, hi) = fmin(fmax(x, lo), hi) */
static ir_ref d_clamp(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref m = ir_op2(c->ir, IR_OP_MAX, A(0), A(1));
    ir_ref dm = max_rule(c, A(0), A(1), d[0], d[1], T);
    return min_rule(c, m, A(2), dm, d[2], T);
}

/* x' inside [0, 1], 0 outside */
static ir_ref d_saturate(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref zero = ir_d_num(c, T, 0.0), one = ir_d_num(c, T, 1.0);
    ir_ref inner = pick(c, ir_op2(c->ir, IR_OP_LESS, one, A(0)), zero, d[0], T);
    return pick(c, ir_op2(c->ir, IR_OP_LESS, A(0), zero), zero, inner, T);
}

/* t = clamp((x - e0) / (e1 - e0), 0, 1), t^2 (3 - 2t)' = 6 t (1 - t) q'
 * with q the unclamped ratio (6 t (1 - t) is 0 where the clamp holds) */
static ir_ref d_smoothstep(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir *ir = c->ir;
    ir_ref num = ir_op2(ir, IR_OP_SUB, A(2), A(0)), den = ir_op2(ir, IR_OP_SUB, A(1), A(0));
    ir_ref q = ir_op2(ir, IR_OP_DIV, num, den);
    ir_ref dq = ir_d_div(c, ir_d_sub(c, ir_d_sub(c, d[2], d[0]),
                                     ir_d_mul(c, q, ir_d_sub(c, d[1], d[0]))), den);
    ir_ref t = ir_op1(ir, IR_OP_SATURATE, q);
    ir_ref k = ir_op2(ir, IR_OP_MUL, ir_d_num(c, T, 6.0),
                      ir_op2(ir, IR_OP_MUL, t, ir_op2(ir, IR_OP_SUB, ir_d_num(c, T, 1.0), t)));
    return guarded(c, k, ir_d_mul(c, k, dq));   /* clamped: 0, even if e0 == e1 */
}

static ir_ref d_select(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return pick(c, A(0), d[1], d[2], T);
}

static ir_ref d_dot(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref a = ir_ref_ok(d[0]) ? ir_op2(c->ir, IR_OP_DOT, d[0], A(1)) : IR_NONE;
    ir_ref b = ir_ref_ok(d[1]) ? ir_op2(c->ir, IR_OP_DOT, A(0), d[1]) : IR_NONE;
    return ir_d_add(c, a, b);
}

/* |a|' = (a . a') / |a| */
static ir_ref d_length(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    return guarded(c, ir_op2(c->ir, IR_OP_DOT, d[0], d[0]),
                   ir_d_div(c, ir_op2(c->ir, IR_OP_DOT, A(0), d[0]), self));
}

/* (a / |a|)' = (a' - u (u . a')) / |a|, u = the result */
static ir_ref d_normalize(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref along = ir_d_mul(c, self, ir_op2(c->ir, IR_OP_DOT, self, d[0]));
    return ir_d_div(c, ir_d_sub(c, d[0], along), ir_op1(c->ir, IR_OP_LENGTH, A(0)));
}

static ir_ref d_cross(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    ir_ref a = ir_ref_ok(d[0]) ? ir_op2(c->ir, IR_OP_CROSS, d[0], A(1)) : IR_NONE;
    ir_ref b = ir_ref_ok(d[1]) ? ir_op2(c->ir, IR_OP_CROSS, A(0), d[1]) : IR_NONE;
    return ir_d_add(c, a, b);
}

/* A texture-space finite difference over the uv's step to the next pixel
 * (what a quad's dFdx of the sampled value is): sample(uv + uv') -
 * sample(uv), the extra sample taking the same gradients (SAMPLE_GRAD). */
static ir_ref d_sample(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d)
{
    if (!ir_ref_ok(d[1]))
        return IR_NONE;
    ir_node m = *n;
    m.arg[1] = ir_op2(c->ir, IR_OP_ADD, A(1), d[1]);
    return ir_op2(c->ir, IR_OP_SUB, ir_node_add(c->ir, &m), self);
}

#undef A
#undef T

/* ---- the table ---------------------------------------------------------- */

static const ir_deriv_fn rule_table[IR_OP_COUNT] = {
#define D(f) d_##f
#define D0 NULL
#define X(id, name, nargs, flags, ports, glsl, type, sem, fin, fp32, cost, deriv) \
    [IR_OP_##id] = deriv,
    IR_OPS(X)
#undef X
#undef D0
#undef D
};

ir_deriv_fn ir_deriv_rule(ir_op op)
{
    assert((unsigned)op < IR_OP_COUNT);
    return rule_table[op];
}
