/* ir_differentiate.c — texture gradients from the compiler: forward-mode
 * differentiation on the IR, for shaders that have no fragment quads (the
 * compute stage of screen-space shading, Moore 2018 "Shading Pass
 * Derivatives"), and for the fragment stage too, so both pick the same
 * mip levels.
 *
 * What: every SAMPLE(tex, uv) becomes SAMPLE_GRAD(tex, uv, duv/dx,
 * duv/dy), which the emitter writes as splat_texture_grad (abi.c:
 * textureLod at textureGrad's level).  The gradients are IR,
 * built from the uv's expression by the chain rule: each op's row of the
 * op table (IR_OPS, ir.h) names its derivative rule (ir_derive_rules.c)
 * next to its GLSL, double and interval semantics, and the leaves are
 *     terrain.position, .height, .uv, view.distance, view.direction
 *         -> DINPUT(input, axis): the prelude's splat_d_<input>(axis), from
 *            FC5's plane-ray intersection in both stages (abi.c)
 *     terrain.normal, .slope, .destruction, painted masks, params,
 *     constants -> 0 (normal and slope would need the heightfield's second
 *            derivatives; they weight, they do not move, texture lookups)
 * and SAMPLE's own rule (a uv that depends on a sample: noise-warped uvs,
 * parallax) is a texture-space finite difference over the uv's step to the
 * neighbouring pixel, exactly what a quad's dFdx of the sampled value is:
 *     d/dx sample(t, uv) = sample(t, uv + duv/dx) - sample(t, uv)
 * (one more sample per axis, taken with the outer sample's gradients).
 * So gradients are exact for any uv expression — linear, parallax,
 * noise-warped or tri-planar — up to that one finite difference.
 *
 * How: ir_rebuild visits the nodes in id order; at a SAMPLE it asks for
 * the derivatives of its uv (memoised per node and axis, built in the new
 * node array, where every operand is already final), so derivative
 * subexpressions are hash-consed with each other and with the values;
 * zero derivatives are IR_NONE and never built.  ir_optimize afterwards
 * folds and drops what is left.
 *
 * Example (.sg): a uv scaled by a param, warped by a noise texture
 *
 *     node w : sample { tex = noise, uv = terrain.uv }
 *     node s : sample { tex = rock,
 *                       uv = add(mul(terrain.uv, scale), w.rgba.xy) }
 *
 * after the pass reads (DINPUT written as the GLSL it emits)
 *
 *     w  = sample_grad(noise, uv, d_uv(0), d_uv(1))
 *     gx = mul(d_uv(0), scale)
 *          + (sample_grad(noise, uv + d_uv(0), d_uv(0), d_uv(1)) - w).xy
 *     gy = … the same with axis 1
 *     s  = sample_grad(rock, mul(uv, scale) + w.xy, gx, gy)
 */
#include "ir.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

/* ---- the walk ----------------------------------------------------------- */

static void memo_grow(ir_dctx *c)
{
    if (c->ir->nnodes <= c->cap)
        return;
    uint32_t cap = c->cap ? c->cap : 64;
    while (cap < c->ir->nnodes)
        cap *= 2;
    for (int a = 0; a < 2; a++) {
        c->memo[a] = realloc(c->memo[a], sizeof(uint32_t) * cap);
        if (!c->memo[a]) {
            fprintf(stderr, "splatc: out of memory\n");
            abort();
        }
        memset(c->memo[a] + c->cap, 0, sizeof(uint32_t) * (cap - c->cap));
    }
    c->cap = cap;
}

/* The derivative of r along c->axis; IR_NONE when zero.  Recursion depth
 * is the depth of r's expression. */
static ir_ref derive(ir_dctx *c, ir_ref r)
{
    memo_grow(c);
    uint32_t m = c->memo[c->axis][r.id];
    if (m)
        return (ir_ref){m - 1};
    ir_node n = *ir_get(c->ir, r);   /* a copy: building may move the array */
    ir_ref d[4] = {IR_NONE, IR_NONE, IR_NONE, IR_NONE};
    bool any = false;
    for (int i = 0; i < n.nargs; i++) {
        /* a texture handle does not move; a SAMPLE_GRAD's gradients are
         * not differentiated again (first order only) */
        if (ir_typeof(c->ir, n.arg[i]) == IR_T_TEX || (n.op == IR_OP_SAMPLE_GRAD && i >= 2))
            continue;
        d[i] = derive(c, n.arg[i]);
        any = any || ir_ref_ok(d[i]);
    }
    ir_deriv_fn rule = ir_deriv_rule((ir_op)n.op);
    ir_ref out = IR_NONE;
    /* a leaf's rule says which inputs move; an op with constant operands
     * is constant */
    if (rule && (n.nargs == 0 || any))
        out = rule(c, &n, r, d);
    assert(!ir_ref_ok(out) || ir_typeof(c->ir, out) == (ir_type)n.type);
    memo_grow(c);
    c->memo[c->axis][r.id] = out.id + 1;
    return out;
}

static void dctx_free(ir_dctx *c)
{
    free(c->memo[0]);
    free(c->memo[1]);
}

ir_ref ir_derivative(ir *ir, ir_ref r, int axis)
{
    ir_dctx c = {.ir = ir, .axis = axis};
    ir_ref d = derive(&c, r);
    dctx_free(&c);
    return ir_d_zero(&(ir_dctx){.ir = ir}, d, ir_typeof(ir, r));
}

ir_ref ir_footprint(ir *ir, ir_ref r)
{
    ir_dctx c = {.ir = ir, .curvature = true};
    ir_type t = ir_typeof(ir, r);
    ir_ref f = IR_NONE;
    for (int a = 0; a < 2; a++) {
        c.axis = a;
        ir_ref d = derive(&c, r);
        if (ir_ref_ok(d))
            f = ir_d_add(&c, f, ir_op1(ir, IR_OP_ABS, d));
    }
    dctx_free(&c);
    return ir_d_zero(&c, f, t);
}

static ir_ref rewrite(ir *dst, const ir_node *n, void *user)
{
    ir_dctx *c = user;
    if (n->op != IR_OP_SAMPLE)
        return ir_node_add(dst, n);
    c->ir = dst;
    ir_ref args[4] = {n->arg[0], n->arg[1]};
    for (int a = 0; a < 2; a++) {
        c->axis = a;
        args[2 + a] = ir_d_zero(c, derive(c, n->arg[1]), IR_T_VEC2);
    }
    return ir_opn(dst, IR_OP_SAMPLE_GRAD, args, 4);
}

bool ir_differentiate(ir *ir)
{
    bool any = false;
    for (uint32_t i = 1; i < ir->nnodes && !any; i++)
        any = ir->nodes[i].op == IR_OP_SAMPLE;
    if (!any)
        return false;
    ir_dctx c = {0};
    ir_rebuild(ir, rewrite, &c);
    dctx_free(&c);
    return true;
}
