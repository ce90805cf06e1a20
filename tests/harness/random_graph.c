/* random_graph.c — random well-typed IR graphs (random_graph.h). */
#include "random_graph.h"

#include <math.h>
#include <string.h>

uint64_t rg_next(rg_rng *r)
{
    uint64_t z = (r->s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

int rg_int(rg_rng *r, int n)
{
    return (int)(rg_next(r) % (uint64_t)n);
}

double rg_uniform(rg_rng *r, double lo, double hi)
{
    double u = (double)(rg_next(r) >> 11) / 9007199254740992.0;   /* [0, 1) */
    return (double)(float)(lo + (hi - lo) * u);
}

ir_type rg_type(rg_rng *r)
{
    return ir_type_vec(1 + rg_int(r, 4));
}

/* Leaves: params "rg.f", "rg.v2", "rg.v3", "rg.v4" (index = width - 1), a
 * painted mask and a texture. */
void rg_setup(ir *ir)
{
    static const char *const names[4] = { "rg.f", "rg.v2", "rg.v3", "rg.v4" };
    for (int w = 1; w <= 4; w++) {
        ir_param p = { .name = (char *)names[w - 1], .type = ir_type_vec(w),
                       .def = { 0.25, 0.5, 0.75, 1.0 }, .lo = -2, .hi = 2 };
        ir_add_param(ir, &p);
    }
    ir_add_painted(ir, "rg_field");
    ir_texture t = { .file = (char *)"rg_grey.png", .filter = IR_FILTER_LINEAR,
                     .mip = IR_FILTER_LINEAR, .wrap = IR_WRAP_REPEAT, .lo = 0, .hi = 1 };
    ir_add_texture(ir, &t);
}

static ir_ref constant(ir *ir, rg_rng *r, ir_type t)
{
    static const double nice[] = { 0.0, 1.0, 0.5, 2.0, -1.0, 0.25, 3.0 };
    double v[4] = {0};
    for (int c = 0; c < ir_type_width(t); c++)
        v[c] = rg_int(r, 2) ? nice[rg_int(r, 7)] : rg_uniform(r, -8, 8);
    return ir_const(ir, t, v);
}

static ir_ref leaf(ir *ir, rg_rng *r, ir_type t)
{
    static const ir_input_kind floats[] = { IR_IN_HEIGHT, IR_IN_SLOPE,
                                            IR_IN_VIEW_DISTANCE, IR_IN_DESTRUCTION };
    int w = ir_type_width(t);
    switch (rg_int(r, 4)) {
    case 0:
        if (t == IR_T_FLOAT)
            return ir_input(ir, floats[rg_int(r, 4)]);
        if (t == IR_T_VEC2)
            return ir_input(ir, IR_IN_UV);
        if (t == IR_T_VEC3)
            return ir_input(ir, rg_int(r, 2) ? IR_IN_NORMAL : IR_IN_POSITION);
        return constant(ir, r, t);
    case 1:
        return ir_param_ref(ir, w - 1);
    case 2:
        return constant(ir, r, t);
    default:
        if (t == IR_T_FLOAT)
            return ir_painted_ref(ir, 0);
        return ir_splat(ir, leaf(ir, r, IR_T_FLOAT), t);
    }
}

/* Componentwise ops, by operand count. */
static const ir_op unary[] = { IR_OP_NEG, IR_OP_ABS, IR_OP_FLOOR, IR_OP_FRACT,
                               IR_OP_SQRT, IR_OP_EXP2, IR_OP_SIN, IR_OP_COS,
                               IR_OP_SATURATE, IR_OP_NORMALIZE };
static const ir_op binary[] = { IR_OP_ADD, IR_OP_SUB, IR_OP_MUL, IR_OP_DIV,
                                IR_OP_MIN, IR_OP_MAX, IR_OP_MOD, IR_OP_POW,
                                IR_OP_STEP, IR_OP_LESS };
static const ir_op ternary[] = { IR_OP_MIX, IR_OP_CLAMP, IR_OP_SMOOTHSTEP,
                                 IR_OP_SELECT };
#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

static ir_ref swizzle_to(ir *ir, rg_rng *r, int n, int depth)
{
    int m = 2 + rg_int(r, 3);                      /* source width 2..4 */
    ir_ref src = rg_expr(ir, r, ir_type_vec(m), depth);
    char comps[5] = {0};
    for (int i = 0; i < n; i++)
        comps[i] = "xyzw"[rg_int(r, m)];
    return ir_swizzle(ir, src, comps);
}

ir_ref rg_expr(ir *ir, rg_rng *r, ir_type t, int depth)
{
    if (depth <= 0 || rg_int(r, 5) == 0)
        return leaf(ir, r, t);
    const int w = ir_type_width(t);
    const int d = depth - 1;
    /* 0-2 componentwise; 3 shape/vector ops by type */
    switch (rg_int(r, 8)) {
    case 0: case 1:
        return ir_op1(ir, unary[rg_int(r, COUNT(unary))], rg_expr(ir, r, t, d));
    case 2: case 3: case 4: {
        ir_op op = binary[rg_int(r, COUNT(binary))];
        ir_ref a = rg_expr(ir, r, t, d);
        /* Materials raise non-negative bases (pow(saturate(x), k)); half
         * the time do the same, so fewer values are NaN. */
        if (op == IR_OP_POW && rg_int(r, 2))
            a = ir_op1(ir, IR_OP_ABS, a);
        return ir_op2(ir, op, a, rg_expr(ir, r, t, d));
    }
    case 5: {
        ir_op op = ternary[rg_int(r, COUNT(ternary))];
        if ((op == IR_OP_CLAMP || op == IR_OP_SMOOTHSTEP) && rg_int(r, 4)) {
            /* Mostly ordered constant edges, as ramps have (unordered
             * edges are undefined in GLSL and cannot be compared). */
            double lo[4], hi[4];
            for (int c = 0; c < w; c++) {
                double u = rg_uniform(r, -4, 4), v = rg_uniform(r, -4, 4);
                lo[c] = fmin(u, v);
                hi[c] = fmax(u, v) + 0.125;
            }
            ir_ref x = rg_expr(ir, r, t, d);
            ir_ref e0 = ir_const(ir, t, lo), e1 = ir_const(ir, t, hi);
            return op == IR_OP_CLAMP ? ir_op3(ir, op, x, e0, e1)
                                     : ir_op3(ir, op, e0, e1, x);
        }
        ir_ref a = rg_expr(ir, r, t, d);
        ir_ref b = rg_expr(ir, r, t, d);
        return ir_op3(ir, op, a, b, rg_expr(ir, r, t, d));
    }
    default:
        break;
    }
    if (w == 1) {
        switch (rg_int(r, 3)) {
        case 0: {
            ir_type v = ir_type_vec(2 + rg_int(r, 3));
            ir_ref a = rg_expr(ir, r, v, d);
            return ir_op2(ir, IR_OP_DOT, a, rg_expr(ir, r, v, d));
        }
        case 1:
            return ir_op1(ir, IR_OP_LENGTH, rg_expr(ir, r, rg_type(r), d));
        default:
            return swizzle_to(ir, r, 1, d);
        }
    }
    switch (rg_int(r, 4)) {
    case 0:
        return ir_splat(ir, rg_expr(ir, r, IR_T_FLOAT, d), t);
    case 1: {                                      /* widths summing to w */
        ir_ref parts[4];
        int n = 0, left = w;
        while (left > 0) {
            int pw = 1 + rg_int(r, left);
            parts[n++] = rg_expr(ir, r, ir_type_vec(pw), d);
            left -= pw;
        }
        return ir_construct(ir, t, parts, n);
    }
    case 2:
        if (t == IR_T_VEC3) {
            ir_ref a = rg_expr(ir, r, IR_T_VEC3, d);
            return ir_op2(ir, IR_OP_CROSS, a, rg_expr(ir, r, IR_T_VEC3, d));
        }
        if (t == IR_T_VEC4)
            return ir_op2(ir, IR_OP_SAMPLE, ir_texture_ref(ir, 0),
                          rg_expr(ir, r, IR_T_VEC2, d));
        return swizzle_to(ir, r, w, d);
    default:
        return swizzle_to(ir, r, w, d);
    }
}

void rg_env(const ir *ir, rg_rng *r, ir_env *env, double *params, double *painted)
{
    memset(env, 0, sizeof *env);
    env->height = rg_uniform(r, 0, 1000);
    env->slope = rg_uniform(r, 0, 1);
    double nx = rg_uniform(r, -1, 1), nz = rg_uniform(r, -1, 1), ny = rg_uniform(r, 0.2, 1);
    double len = sqrt(nx * nx + ny * ny + nz * nz);
    env->normal[0] = (float)(nx / len);
    env->normal[1] = (float)(ny / len);
    env->normal[2] = (float)(nz / len);
    env->position[0] = rg_uniform(r, 0, 4096);
    env->position[1] = env->height;
    env->position[2] = rg_uniform(r, 0, 4096);
    env->uv[0] = rg_uniform(r, 0, 1);
    env->uv[1] = rg_uniform(r, 0, 1);
    env->view_distance = rg_uniform(r, 0, 3000);
    env->destruction = rg_int(r, 2) ? 0.0 : rg_uniform(r, 0, 1);
    for (int i = 0; i < 4 * ir->nparams; i++)
        params[i] = rg_uniform(r, -2, 2);
    for (int i = 0; i < ir->npainted; i++)
        painted[i] = rg_uniform(r, 0, 1);
    env->params = params;
    env->painted = painted;
}
