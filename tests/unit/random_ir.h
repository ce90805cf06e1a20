/* random_ir.h — seeded, deterministic generator of random well-typed IR
 * graphs and input regions, for the back-end agreement tests
 * (test_random_agree.c here, and the GPU harness, which evaluates the same
 * graphs through the GLSL emitter).  Header-only: include it in one .c.
 *
 *   random_ir_rng rng = {seed};
 *   ir r; ir_init(&r);
 *   random_ir_setup(&r);                        // params, a texture, a mask
 *   ir_ref e = random_ir_expr(&r, &rng, IR_T_VEC3, 5, NULL);
 *   ir_ienv box; random_ir_box(&r, &rng, &box, params_iv, painted_iv);
 *   ir_env pt;   random_ir_point(&r, &rng, &box, &pt, params, painted);
 *
 * Every op of IR_OPS can appear (random_ir_opts.exclude masks some out, e.g.
 * a GPU test may exclude ops whose float and double results legitimately
 * differ a lot, like huge pow or exp2 arguments).  The single texture
 * reads a smooth function with channels in [0, 1] (random_ir_sample).
 */
#ifndef SPLAT_RANDOM_IR_H
#define SPLAT_RANDOM_IR_H

#include "ir.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

typedef struct random_ir_rng { uint64_t state; } random_ir_rng;

typedef struct random_ir_opts {
    uint64_t exclude;        /* bit (1 << op): never generate that op    */
    double   const_mag;      /* typical constant magnitude (0: 4)        */
} random_ir_opts;

enum { RANDOM_IR_NPARAMS = 3, RANDOM_IR_NPAINTED = 1 };

static inline uint64_t random_ir_next(random_ir_rng *r)
{
    /* splitmix64 */
    uint64_t z = (r->state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static inline double random_ir_unit(random_ir_rng *r)   /* [0, 1) */
{
    return (double)(random_ir_next(r) >> 11) * 0x1.0p-53;
}

static inline int random_ir_int(random_ir_rng *r, int n)  /* [0, n) */
{
    return (int)(random_ir_next(r) % (uint64_t)n);
}

static inline double random_ir_range(random_ir_rng *r, double lo, double hi)
{
    return lo + (hi - lo) * random_ir_unit(r);
}

/* Params (float [0, 1], vec3 [-2, 2], a fixed float), one texture with
 * channels in [0, 1], one painted mask. */
static inline void random_ir_setup(ir *ir)
{
    ir_param p0 = {.name = "rnd.a", .type = IR_T_FLOAT, .def = {0.25}, .lo = 0, .hi = 1};
    ir_param p1 = {.name = "rnd.v", .type = IR_T_VEC3, .def = {0.5, -1, 2}, .lo = -2, .hi = 2};
    ir_param p2 = {.name = "rnd.fixed", .type = IR_T_FLOAT, .def = {3}, .lo = 3, .hi = 3};
    ir_add_param(ir, &p0);
    ir_add_param(ir, &p1);
    ir_add_param(ir, &p2);
    ir_texture t = {.file = "random.png", .lo = 0, .hi = 1};
    ir_add_texture(ir, &t);
    ir_add_painted(ir, "rnd.mask");
}

/* The texture of random_ir_setup, for ir_env.sample: smooth, in [0, 1]. */
static inline void random_ir_sample(void *user, int texture, double u, double v,
                                    double rgba[4])
{
    (void)user;
    /* like a GPU sampler, any uv (NaN and inf too) reads some texel */
    if (!isfinite(u))
        u = 0;
    if (!isfinite(v))
        v = 0;
    for (int c = 0; c < 4; c++)
        rgba[c] = 0.5 + 0.5 * sin(3.0 * u + 5.0 * v * (c + 1) + texture + c);
}

static inline double random_ir_constant(random_ir_rng *r, const random_ir_opts *o)
{
    static const double special[] = {0.0, 1.0, -1.0, 0.5, 2.0, -0.0, 1e-3, 100.0};
    double mag = o && o->const_mag > 0 ? o->const_mag : 4.0;
    switch (random_ir_int(r, 4)) {
    case 0:  return special[random_ir_int(r, 8)];
    case 1:  return (double)(random_ir_int(r, 9) - 4);
    default: return random_ir_range(r, -mag, mag);
    }
}

static inline bool random_ir_allowed(const random_ir_opts *o, ir_op op)
{
    return !o || !(o->exclude >> op & 1);
}

static inline ir_ref random_ir_expr(ir *ir, random_ir_rng *r, ir_type t, int depth,
                             const random_ir_opts *o);

static inline ir_ref random_ir_leaf(ir *ir, random_ir_rng *r, ir_type t,
                                    const random_ir_opts *o)
{
    int w = ir_type_width(t);
    for (;;) {
        switch (random_ir_int(r, 6)) {
        case 0: case 1: {
            double v[4];
            for (int c = 0; c < 4; c++)
                v[c] = random_ir_constant(r, o);
            return ir_const(ir, t, v);
        }
        case 2:
            if (t == IR_T_FLOAT) {
                static const ir_input_kind in[] = {IR_IN_HEIGHT, IR_IN_SLOPE,
                    IR_IN_VIEW_DISTANCE, IR_IN_DESTRUCTION};
                return ir_input(ir, in[random_ir_int(r, 4)]);
            }
            if (t == IR_T_VEC2)
                return ir_input(ir, IR_IN_UV);
            if (t == IR_T_VEC3)
                return ir_input(ir, random_ir_int(r, 2) ? IR_IN_NORMAL : IR_IN_POSITION);
            break;
        case 3:
            if (t == IR_T_FLOAT)
                return ir_param_ref(ir, random_ir_int(r, 2) ? 0 : 2);
            if (t == IR_T_VEC3)
                return ir_param_ref(ir, 1);
            break;
        case 4:
            if (t == IR_T_FLOAT)
                return ir_painted_ref(ir, 0);
            break;
        case 5:
            if (w > 1 && random_ir_allowed(o, IR_OP_SPLAT))
                return ir_splat(ir, random_ir_leaf(ir, r, IR_T_FLOAT, o), t);
            break;
        }
    }
}

static inline ir_type random_ir_type(random_ir_rng *r, int min_width)
{
    return ir_type_vec(min_width + random_ir_int(r, 5 - min_width));
}

/* A random expression of type t (float..vec4) with at most `depth` levels
 * of ops above the leaves. */
static inline ir_ref random_ir_expr(ir *ir, random_ir_rng *r, ir_type t, int depth,
                             const random_ir_opts *o)
{
    int w = ir_type_width(t);
    if (depth <= 0 || random_ir_int(r, 6) == 0)
        return random_ir_leaf(ir, r, t, o);
    for (int tries = 0; tries < 100; tries++) {
        /* SPLAT..CROSS: the derivative pass's ops come after CROSS */
        ir_op op = (ir_op)(IR_OP_SPLAT + random_ir_int(r, IR_OP_CROSS + 1 - IR_OP_SPLAT));
        if (!random_ir_allowed(o, op))
            continue;
        const ir_opinfo *info = ir_opinfo_get(op);
        int d = depth - 1;
        if (info->flags & IR_COMPONENTWISE) {
            ir_ref a[3];
            for (int i = 0; i < info->nargs; i++)
                a[i] = random_ir_expr(ir, r, t, d, o);
            return ir_opn(ir, op, a, info->nargs);
        }
        switch (op) {
        case IR_OP_SPLAT:
            if (w > 1)
                return ir_splat(ir, random_ir_expr(ir, r, IR_T_FLOAT, d, o), t);
            break;
        case IR_OP_SWIZZLE: {
            ir_type from = random_ir_type(r, 2);
            ir_ref a = random_ir_expr(ir, r, from, d, o);
            char comps[5] = {0};
            for (int i = 0; i < w; i++)
                comps[i] = "xyzw"[random_ir_int(r, ir_type_width(from))];
            return ir_swizzle(ir, a, comps);
        }
        case IR_OP_CONSTRUCT: {
            if (w < 2)
                break;
            ir_ref a[4];
            int n = 0;
            for (int left = w; left > 0; n++) {
                int part = 1 + random_ir_int(r, left == w ? left - 1 : left);
                a[n] = random_ir_expr(ir, r, ir_type_vec(part), d, o);
                left -= part;
            }
            return ir_construct(ir, t, a, n);
        }
        case IR_OP_SAMPLE: {
            ir_ref s = ir_op2(ir, IR_OP_SAMPLE, ir_texture_ref(ir, 0),
                              random_ir_expr(ir, r, IR_T_VEC2, d, o));
            if (t == IR_T_VEC4)
                return s;
            static const char *const sw[] = {"", "w", "yx", "rgb"};
            return ir_swizzle(ir, s, sw[w]);
        }
        case IR_OP_DOT:
        case IR_OP_LENGTH: {
            if (t != IR_T_FLOAT)
                break;
            ir_type from = random_ir_type(r, 1);
            ir_ref a = random_ir_expr(ir, r, from, d, o);
            if (op == IR_OP_LENGTH)
                return ir_op1(ir, op, a);
            ir_ref b = random_ir_int(r, 3) == 0 ? a : random_ir_expr(ir, r, from, d, o);
            return ir_op2(ir, op, a, b);
        }
        case IR_OP_NORMALIZE:
            return ir_op1(ir, op, random_ir_expr(ir, r, t, d, o));
        case IR_OP_CROSS:
            if (t == IR_T_VEC3)
                return ir_op2(ir, op, random_ir_expr(ir, r, t, d, o),
                              random_ir_expr(ir, r, t, d, o));
            break;
        default:
            break;
        }
    }
    return random_ir_leaf(ir, r, t, o);
}

/* An interval inside [lo, hi]: sometimes a point, sometimes all of it. */
static inline ir_iv random_ir_subrange(random_ir_rng *r, double lo, double hi)
{
    double a = random_ir_range(r, lo, hi), b = random_ir_range(r, lo, hi);
    switch (random_ir_int(r, 5)) {
    case 0:  return (ir_iv){a, a};
    case 1:  return (ir_iv){lo, hi};
    default: return (ir_iv){fmin(a, b), fmax(a, b)};
    }
}

/* A random input region; params[] and painted[] (RANDOM_IR_NPARAMS,
 * RANDOM_IR_NPAINTED entries) receive their intervals. */
static inline void random_ir_box(const ir *ir, random_ir_rng *r, ir_ienv *box,
                                 ir_iv *params, ir_iv *painted)
{
    memset(box, 0, sizeof *box);
    box->height = random_ir_subrange(r, -50, 500);
    box->slope = random_ir_subrange(r, 0, 1);
    for (int c = 0; c < 3; c++) {
        box->normal[c] = random_ir_subrange(r, -1, 1);
        box->position[c] = random_ir_subrange(r, -100, 1000);
    }
    for (int c = 0; c < 2; c++)
        box->uv[c] = random_ir_subrange(r, 0, 1);
    box->view_distance = random_ir_subrange(r, 0, 2000);
    box->destruction = random_ir_subrange(r, 0, 1);
    for (int i = 0; i < ir->nparams && i < RANDOM_IR_NPARAMS; i++)
        params[i] = ir->params[i].lo == ir->params[i].hi
                        ? (ir_iv){ir->params[i].def[0], ir->params[i].def[0]}
                        : random_ir_subrange(r, ir->params[i].lo, ir->params[i].hi);
    for (int i = 0; i < RANDOM_IR_NPAINTED; i++)
        painted[i] = random_ir_subrange(r, 0, 1);
    box->params = params;
    box->painted = painted;
}

static inline double random_ir_in(random_ir_rng *r, ir_iv x)
{
    switch (random_ir_int(r, 6)) {
    case 0:  return x.lo;
    case 1:  return x.hi;
    default: return fmin(fmax(random_ir_range(r, x.lo, x.hi), x.lo), x.hi);
    }
}

/* A random point of `box`; params (4 per param) and painted receive the
 * values and env points at them. */
static inline void random_ir_point(const ir *ir, random_ir_rng *r, const ir_ienv *box,
                                   ir_env *env, double *params, double *painted)
{
    memset(env, 0, sizeof *env);
    env->height = random_ir_in(r, box->height);
    env->slope = random_ir_in(r, box->slope);
    for (int c = 0; c < 3; c++) {
        env->normal[c] = random_ir_in(r, box->normal[c]);
        env->position[c] = random_ir_in(r, box->position[c]);
    }
    for (int c = 0; c < 2; c++)
        env->uv[c] = random_ir_in(r, box->uv[c]);
    env->view_distance = random_ir_in(r, box->view_distance);
    env->destruction = random_ir_in(r, box->destruction);
    for (int i = 0; i < ir->nparams && i < RANDOM_IR_NPARAMS; i++)
        for (int c = 0; c < 4; c++)
            params[4 * i + c] = c < ir_type_width(ir->params[i].type)
                                    ? random_ir_in(r, box->params[i]) : 0.0;
    for (int i = 0; i < RANDOM_IR_NPAINTED; i++)
        painted[i] = random_ir_in(r, box->painted[i]);
    env->params = params;
    env->painted = painted;
    env->sample = random_ir_sample;
}

#endif
