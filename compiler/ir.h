/* ir.h — the splatc IR: a typed, hash-consed DAG of pure values.
 *
 * One `ir` holds the nodes of one material, or of every material of a
 * composite (so subtrees shared between materials are one node).  Nodes live
 * in an array and are named by `ir_ref` (an index; 0 is "no value").  Every
 * node is created through the builder, which hash-conses on
 * (op, type, args, imm, val): building the same expression twice returns the
 * same ref.  Commutative ops put their operands in canonical (ascending id)
 * order before hashing.
 *
 * Each op's semantics live once, in the op table (ir_ops.c): its .sg name and
 * port names, its type rule, its GLSL form, its double-precision evaluation,
 * its interval evaluation and its derivative rule.  The back ends (GLSL
 * emitter, CPU reference, interval evaluator, forward-mode differentiation)
 * all read that table.
 *
 * Sections below: types, ops, the ir and its builder (ir.c), passes
 * (opt_*.c, driven by ir_optimize in opt.c), derivatives
 * (ir_differentiate.c: texture gradients for the compute stage), validator
 * (ir_validate.c), dump (ir_dump.c), evaluators (ir_eval.c, ir_interval.c),
 * GLSL (glsl.c).
 */
#ifndef SPLAT_IR_H
#define SPLAT_IR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* ---- types ------------------------------------------------------------ */

typedef enum ir_type {
    IR_T_ERROR = 0,  /* result of a type rule that rejects its operands */
    IR_T_FLOAT,
    IR_T_VEC2,
    IR_T_VEC3,
    IR_T_VEC4,
    IR_T_TEX,        /* a texture resource handle (2D, combined sampler) */
    IR_T_COUNT
} ir_type;

int         ir_type_width(ir_type t);      /* components: 1..4; 0 for handles */
ir_type     ir_type_vec(int width);        /* 1 -> FLOAT, 2 -> VEC2 ...      */
const char *ir_type_name(ir_type t);       /* "float", "vec3", "texture"     */
ir_type     ir_type_from_name(const char *s); /* IR_T_ERROR if unknown       */

/* ---- ops --------------------------------------------------------------- */

/* Terrain and view inputs (OP_INPUT's imm): one row per input, every fact
 * about it in its row.  ir_input_get (ir_ops.c) returns a row as an
 * ir_input_info; the front end, the evaluators, the GLSL emitter, the
 * compositor and `splatc eval --at` all loop over it.
 *
 *   X(id, sg_name, type, glsl, key, ev, iv, domain, hoist, dglsl)
 *     sg_name  what a graph writes ("terrain.height")
 *     glsl     the ABI prelude's accessor (abi.h)
 *     key      the `splatc eval --at KEY=…` name
 *     ev       the ir_env field holding its value (ir_eval)
 *     iv       IV(field): the ir_ienv field holding its bounds
 *              (ir_interval); IV_NONE: bounded by its domain alone
 *     domain   bounds of every value it can take: what `splatc eval`
 *              and a terrain region assume until told more
 *              (IR_DOM_* in ir_ops.c, per component)
 *     hoist    composites read it once into a local (its accessor costs
 *              more than a register read; compose.c)
 *     dglsl    its screen-space derivative rule (ir_differentiate.c): the
 *              prelude's splat_d_<input>(axis) accessor the DINPUT leaf
 *              reads (abi.c), or NULL: taken as 0 (destruction is
 *              piecewise).  normal and slope have one (the heightfield's
 *              normal one pixel over, minus this one's: 9 gathers), read
 *              only by footprint derivatives (fwidth, ir_footprint);
 *              texture gradients take them as 0 (they weight, they do not
 *              move, texture lookups)
 *
 * A new input: a row here, its ir_env (and ir_ienv) field below, its
 * accessor in the ABI prelude (abi.c), and in terrain.c if a region
 * bounds it tighter than its domain. */
#define IR_INPUTS(X)                                                              \
    X(HEIGHT,         "terrain.height",      IR_T_FLOAT, "splat_height()",        \
      "height",       height,         IV(height),        ALL,    1,               \
      "splat_d_height")                                                /* m        */ \
    X(SLOPE,          "terrain.slope",       IR_T_FLOAT, "splat_slope()",         \
      "slope",        slope,          IV(slope),         UNIT,   1,               \
      "splat_d_slope")                                                 /* 1-n.y    */ \
    X(NORMAL,         "terrain.normal",      IR_T_VEC3,  "splat_normal()",        \
      "normal",       normal,         IV(normal),        NORMAL, 1,               \
      "splat_d_normal")                                                /* world    */ \
    X(POSITION,       "terrain.position",    IR_T_VEC3,  "splat_position()",      \
      "position",     position,       IV(position),      ALL,    1,               \
      "splat_d_position")                                              /* local m  */ \
    X(UV,             "terrain.uv",          IR_T_VEC2,  "splat_uv()",            \
      "uv",           uv,             IV(uv),            UNIT,   0,               \
      "splat_d_uv")                                                    /* 0..1     */ \
    X(VIEW_DISTANCE,  "view.distance",       IR_T_FLOAT, "splat_view_distance()", \
      "distance",     view_distance,  IV(view_distance), DIST,   1,               \
      "splat_d_view_distance")                                         /* m        */ \
    X(DESTRUCTION,    "terrain.destruction", IR_T_FLOAT, "splat_destruction()",   \
      "destruction",  destruction,    IV(destruction),   UNIT,   1,               \
      NULL)                                                            /* 0 = none */ \
    X(VIEW_DIRECTION, "view.direction",      IR_T_VEC3,  "splat_view_direction()",\
      "direction",    view_direction, IV_NONE,           SIGNED, 0,               \
      "splat_d_view_direction")                                        /* unit     */ \
    X(CAVITY,         "terrain.cavity",      IR_T_FLOAT, "splat_cavity()",        \
      "cavity",       cavity,         IV_NONE,           ALL,    1,               \
      NULL)                                                            /* m, + in hollows */ \
    X(SHADING_LOD,    "view.shading_lod",    IR_T_FLOAT, "splat_shading_lod()",   \
      "shading_lod",  shading_lod,    IV_NONE,           UNIT,   0,               \
      NULL)                                                            /* 0 or 1   */

/* The type is `enum ir_input` (alias ir_input_kind): the plain name
 * `ir_input` is the builder function below. */
typedef enum ir_input {
#define X(id, ...) IR_IN_##id,
    IR_INPUTS(X)
#undef X
    IR_IN_COUNT
} ir_input_kind;

/* fp32 error classes: how far a GPU's fp32 result of an op may lie from
 * the double reference (u = 2^-24).  The GPU-agreement harness
 * (tests/harness/harness_ref.c) turns each class into a bound; it switches
 * on the class without a default, so a new class that it does not know is
 * a compile error there, and every op row must name one. */
#define IR_FP32_CLASSES(X)                                                       \
    X(EXACT)      /* exact in fp32 (neg abs floor min max splat …)          */ \
    X(LITERAL)    /* u|v|: a constant rounded to fp32                       */ \
    X(ROUNDED)    /* u|r|: correctly rounded (add sub mul)                  */ \
    X(ULP3)       /* 3u|r|: div, sqrt (2.5 ulp)                             */ \
    X(FRACT)      /* u                                                      */ \
    X(MOD)        /* 4u(|x|+|y|), ill-conditioned near integer x/y          */ \
    X(EXP2)       /* (3+2|x|)u|r|                                           */ \
    X(POW)        /* (8+16|y|(1+|log2 x|))u|r|, undefined x<0               */ \
    X(TRIG)       /* 32u + 8u|x| absolute                                   */ \
    X(MIX)        /* 2u(|a|+|b|)(1+|t|) + u|r|                              */ \
    X(CLAMP)      /* exact; undefined when lo > hi                          */ \
    X(SMOOTHSTEP) /* 1.5 e_t + 4u; undefined when e0 >= e1                  */ \
    X(DOT)        /* (n+1)u sum|a_i b_i|                                    */ \
    X(LENGTH)     /* 4u|r|                                                  */ \
    X(NORMALIZE)  /* 6u per component                                       */ \
    X(CROSS)      /* 2u(|a_j b_k| + |a_k b_j|)                              */ \
    X(SAMPLE)     /* sub-texel weights and coordinate rounding              */

typedef enum ir_fp32_class {
#define X(id) IR_FP32_##id,
    IR_FP32_CLASSES(X)
#undef X
    IR_FP32_COUNT
} ir_fp32_class;

/* Finiteness: when an op's result is provably neither NaN nor inf
 * (opt_fold may then fold x * 0 to 0).  IR_FIN_ARGS(mask): when the
 * operands in `mask` (bit i = operand i) are; IR_FIN_DATA: decided by the
 * leaf's data (a constant's value, a param's range, a texture's range). */
enum { IR_FIN_NO = 0, IR_FIN_YES = 1, IR_FIN_DATA = 2, IR_FIN_ARGS_BIT = 0x100 };
#define IR_FIN_ARGS(mask) (IR_FIN_ARGS_BIT | (mask))

/* THE op table: one row per op, every fact about the op in its row.
 *
 *   X(id, sg_name, nargs, flags, ports, glsl, type, sem, fin, fp32, cost,
 *     deriv)
 *     sg_name  .sg node type; NULL for ops an artist does not write
 *     nargs    operand count (4 for CONSTRUCT means "up to 4")
 *     flags    IR_COMMUTATIVE | IR_COMPONENTWISE | IR_NAN_PROPAGATES
 *     ports    input port names in operand order: P1 ("x"), P2 ("a",
 *              "b"), PORTS(...), NOPORTS
 *     glsl     GLSL form, $i = operand i ("mix($0, $1, $2)")
 *     type     type rule (ty_* in ir_ops.c): result type or IR_T_ERROR
 *     sem      double-precision value and sound interval, written side by
 *              side in ir_ops.c: CW(f) = scalar e_f/i_f applied per
 *              component; NODE(f) = e_f/i_f on the whole node; ENV = the
 *              evaluator's environment supplies it (leaves, SAMPLE)
 *     fin      IR_FIN_*: when the result is provably finite (opt_fold)
 *     fp32     IR_FP32_* error class (the GPU-agreement harness)
 *     cost     op cost units per component (below)
 *     deriv    forward-mode derivative rule (ir_differentiate.c): D(f) =
 *              d_f in ir_derive_rules.c, building the derivative as IR from the
 *              operands and theirs; D0: always 0 (constants, floor, step…)
 *
 * A row is positional: a row missing a column does not compile.  To add a
 * column (e.g. the forward-mode derivative): add a parameter at the END of
 * the list above and in every row, a field at the end of ir_opinfo, and
 * its expansion in ir_ops.c's ROW macro (marked "new columns here").
 *
 * Cost units (ir_node_cost, ir_cost): an estimate of ALU work, 1 = one
 * fp32 add/mul/compare on one component; transcendental ops cost more,
 * a texture sample 4 per component (16 for its vec4).  A node costs
 * `cost` times the widest of its result and operands (so a vec3 add is 3,
 * dot(vec3, vec3) is 3 x 2).  Leaves, swizzles, splats and constructs are
 * free (register moves).  The screen-space path picks the cheapest
 * covering combination by it; shading LOD will rank materials by it.
 * Relative, not cycles: keep new rows consistent with the old ones.
 *
 * A new op touches this row and its e_/i_ functions in ir_ops.c (and
 * glsl.c only if its GLSL form is not a template).
 */
#define IR_OPS(X)                                                                           \
    /* leaves: values come from the environment (ir_env, glsl_names)  */                    \
    X(CONST,     NULL,  0, 0, NOPORTS, "<literal>",         ty_leaf, ENV, IR_FIN_DATA, LITERAL, 0, D0) \
    X(INPUT,     NULL,  0, 0, NOPORTS, "splat_<input>()",   ty_leaf, ENV, IR_FIN_YES,  EXACT, 0, D(input))   \
    X(PARAM,     NULL,  0, 0, NOPORTS, "<names.param[i]>",  ty_leaf, ENV, IR_FIN_DATA, EXACT, 0, D0)   \
    X(TEXTURE,   NULL,  0, 0, NOPORTS, "<names.texture[i]>",ty_leaf, ENV, IR_FIN_NO,   EXACT, 0, D0)   \
    X(PAINTED,   NULL,  0, 0, NOPORTS, "<names.painted[i]>",ty_leaf, ENV, IR_FIN_YES,  EXACT, 0, D0)   \
    /* shape: SPLAT float -> vecN (type says N); SWIZZLE imm = IR_SWZ; */                   \
    /* CONSTRUCT vecN from floats/vectors (nargs = operands)           */                   \
    X(SPLAT,     NULL,  1, 0, P1, "vecN($0)",       ty_splat,     NODE(splat),     IR_FIN_ARGS(1), EXACT, 0, D(linear)) \
    X(SWIZZLE,   NULL,  1, 0, P1, "$0.<xyzw>",      ty_swizzle,   NODE(swizzle),   IR_FIN_ARGS(1), EXACT, 0, D(linear)) \
    X(CONSTRUCT, NULL,  4, 0, PORTS("x", "y", "z", "w"), "vecN($0, ...)", ty_construct, NODE(construct), \
      IR_FIN_NO, EXACT, 0, D(linear))                                                                  \
    /* texture: (tex, uv) -> vec4 */                                                        \
    X(SAMPLE,    "sample", 2, 0, PORTS("tex", "uv"), "texture($0, $1)", ty_sample, ENV,     \
      IR_FIN_DATA, SAMPLE, 4, D(sample))                                                               \
    /* componentwise arithmetic: operands of one type (lowering splats) */                  \
    X(ADD,   "add",   2, IR_COMMUTATIVE | IR_CWN, P2, "$0 + $1",     ty_same, CW(add),   IR_FIN_NO, ROUNDED, 1, D(add)) \
    X(SUB,   "sub",   2, IR_CWN,                  P2, "$0 - $1",     ty_same, CW(sub),   IR_FIN_NO, ROUNDED, 1, D(sub)) \
    X(MUL,   "mul",   2, IR_COMMUTATIVE | IR_CWN, P2, "$0 * $1",     ty_same, CW(mul),   IR_FIN_NO, ROUNDED, 1, D(mul)) \
    X(DIV,   "div",   2, IR_CWN,                  P2, "$0 / $1",     ty_same, CW(div),   IR_FIN_NO, ULP3, 4, D(div))    \
    X(NEG,   "neg",   1, IR_CWN,                  P1, "-($0)",       ty_same, CW(neg),   IR_FIN_NO, EXACT, 1, D(linear))   \
    X(MIN,   "min",   2, IR_COMMUTATIVE | IR_COMPONENTWISE, P2, "min($0, $1)", ty_same, CW(min), IR_FIN_NO, EXACT, 1, D(min)) \
    X(MAX,   "max",   2, IR_COMMUTATIVE | IR_COMPONENTWISE, P2, "max($0, $1)", ty_same, CW(max), IR_FIN_NO, EXACT, 1, D(max)) \
    X(ABS,   "abs",   1, IR_CWN,                  P1, "abs($0)",     ty_same, CW(abs),   IR_FIN_NO, EXACT, 1, D(abs))   \
    X(FLOOR, "floor", 1, IR_CWN,                  P1, "floor($0)",   ty_same, CW(floor), IR_FIN_NO, EXACT, 1, D0)   \
    X(FRACT, "fract", 1, IR_CWN,                  P1, "fract($0)",   ty_same, CW(fract), IR_FIN_NO, FRACT, 2, D(fract))   \
    X(MOD,   "mod",   2, IR_CWN, PORTS("x", "y"), "mod($0, $1)",     ty_same, CW(mod),   IR_FIN_NO, MOD, 6, D(mod))     \
    X(SQRT,  "sqrt",  1, IR_CWN,                  P1, "sqrt($0)",    ty_same, CW(sqrt),  IR_FIN_NO, ULP3, 4, D(sqrt))    \
    X(POW,   "pow",   2, IR_CWN, PORTS("x", "y"), "pow($0, $1)",     ty_same, CW(pow),   IR_FIN_NO, POW, 9, D(pow))     \
    X(EXP2,  "exp2",  1, IR_CWN,                  P1, "exp2($0)",    ty_same, CW(exp2),  IR_FIN_NO, EXP2, 4, D(exp2))    \
    X(SIN,   "sin",   1, IR_CWN,                  P1, "sin($0)",     ty_same, CW(sin),   IR_FIN_NO, TRIG, 8, D(sin))    \
    X(COS,   "cos",   1, IR_CWN,                  P1, "cos($0)",     ty_same, CW(cos),   IR_FIN_NO, TRIG, 8, D(cos))    \
    X(MIX,   "mix",   3, IR_CWN, PORTS("a", "b", "t"), "mix($0, $1, $2)", ty_same, CW(mix), IR_FIN_NO, MIX, 3, D(mix)) \
    X(CLAMP, "clamp", 3, IR_COMPONENTWISE, PORTS("x", "lo", "hi"), "clamp($0, $1, $2)", ty_same, CW(clamp), \
      IR_FIN_ARGS(6), CLAMP, 2, D(clamp))                                                             \
    X(SATURATE, "saturate", 1, IR_COMPONENTWISE, P1, "clamp($0, 0.0, 1.0)", ty_same, CW(saturate), \
      IR_FIN_YES, EXACT, 1, D(saturate))                                                                 \
    X(STEP,  "step",  2, IR_COMPONENTWISE, PORTS("edge", "x"), "step($0, $1)", ty_same, CW(step), \
      IR_FIN_YES, EXACT, 1, D0)                                                                 \
    X(SMOOTHSTEP, "smoothstep", 3, IR_COMPONENTWISE, PORTS("e0", "e1", "x"),                \
      "smoothstep($0, $1, $2)", ty_same, CW(smoothstep), IR_FIN_YES, SMOOTHSTEP, 8, D(smoothstep))         \
    /* float forms; the emitter writes lessThan / a bvec mix for vectors */                 \
    X(LESS,  "less",  2, IR_COMPONENTWISE, P2, "float($0 < $1)", ty_same, CW(less),          \
      IR_FIN_YES, EXACT, 1, D0)                                    /* a < b ? 1 : 0  */         \
    X(SELECT, "select", 3, IR_COMPONENTWISE, PORTS("c", "a", "b"), "($0 != 0.0 ? $1 : $2)", \
      ty_same, CW(select), IR_FIN_NO, EXACT, 1, D(select))                /* c != 0 ? a : b */         \
    /* vector */                                                                            \
    X(DOT,       "dot",       2, IR_COMMUTATIVE, P2, "dot($0, $1)",   ty_dot,    NODE(dot),       \
      IR_FIN_NO, DOT, 2, D(dot))                                                                    \
    X(LENGTH,    "length",    1, 0, P1, "length($0)",    ty_length, NODE(length),    IR_FIN_NO, LENGTH, 3, D(length))    \
    X(NORMALIZE, "normalize", 1, 0, P1, "normalize($0)", ty_same,   NODE(normalize), IR_FIN_NO, NORMALIZE, 4, D(normalize)) \
    X(CROSS,     "cross",     2, 0, P2, "cross($0, $1)", ty_cross,  NODE(cross),     IR_FIN_NO, CROSS, 2, D(cross)) \
    /* derivatives (ir_differentiate.c; not written in .sg).  Kept last:  */                 \
    /* random graph generators draw SPLAT..CROSS.  DINPUT: imm =          */                 \
    /* IR_DINPUT_IMM(input, axis), the input row's dglsl accessor;        */                 \
    /* SAMPLE_GRAD (tex, uv, duv/dx, duv/dy): the reference samples as    */                 \
    /* SAMPLE does (level 0); LOG2: pow's rule, and .sg's log2 (never    */                 \
    /* drawn by the harness: x <= 0 is undefined in GLSL)                 */               \
    X(DINPUT,    NULL,  0, 0, NOPORTS, "splat_d_<input>(axis)", ty_leaf, ENV, IR_FIN_NO, EXACT, 0, D0) \
    X(SAMPLE_GRAD, NULL, 4, 0, PORTS("tex", "uv", "ddx", "ddy"), "splat_texture_grad($0, $1, $2, $3)", \
      ty_sample_grad, ENV, IR_FIN_DATA, SAMPLE, 4, D(sample))                               \
    X(LOG2,      "log2", 1, IR_CWN, P1, "log2($0)", ty_same, CW(log2), IR_FIN_NO, ULP3, 4, D(log2)) \
    /* FWIDTH: .sg's fwidth, |d/dx| + |d/dy| of its operand over one      */                 \
    /* pixel; lowering expands it (ir_footprint), so the IR never holds    */                 \
    /* one: its value 0 and bounds [0, inf] are never read                 */                 \
    X(FWIDTH,    "fwidth", 1, IR_COMPONENTWISE, P1, "fwidth($0)", ty_same, CW(fwidth), IR_FIN_NO, EXACT, 2, D0)

/* IR_NAN_PROPAGATES: a NaN operand component gives a NaN result component
 * (the interval code short-circuits such operands to [-inf, inf]). */
enum { IR_COMMUTATIVE = 1, IR_COMPONENTWISE = 2, IR_NAN_PROPAGATES = 4 };
#define IR_CWN (IR_COMPONENTWISE | IR_NAN_PROPAGATES)

typedef enum ir_op {
#define X(id, ...) IR_OP_##id,
    IR_OPS(X)
#undef X
    IR_OP_COUNT
} ir_op;

/* DINPUT immediates: the screen-space derivative of terrain input `input`
 * along axis 0 (d/dx, one pixel right) or 1 (d/dy, one pixel down).
 * IR_DINPUT_FOOTPRINT marks a footprint's (fwidth, ir_footprint): the
 * same value; the normal's is written through the prelude's splat_fp,
 * which the CPU shading LOD (abi.h SPLAT_SPEC_LOD) makes 0. */
#define IR_DINPUT_IMM(input, axis) ((uint32_t)(input) | (uint32_t)(axis) << 8)
#define IR_DINPUT_INPUT(imm)       ((int)((imm) & 255))
#define IR_DINPUT_AXIS(imm)        ((int)(((imm) >> 8) & 255))
#define IR_DINPUT_FOOTPRINT        (1u << 16)

/* Swizzle immediates: n components, each 0..3 (x y z w). */
#define IR_SWZ(n, a, b, c, d) \
    ((uint32_t)(n) | (uint32_t)(a) << 4 | (uint32_t)(b) << 6 | (uint32_t)(c) << 8 | (uint32_t)(d) << 10)
#define IR_SWZ_N(imm)    ((int)((imm) & 15))
#define IR_SWZ_C(imm, i) ((int)(((imm) >> (4 + 2 * (i))) & 3))

typedef struct ir_iv ir_iv;    /* an interval, defined with the evaluators */
struct ir_node;
struct ir_ref;
typedef struct ir_dctx ir_dctx;  /* a differentiation in progress (below) */

/* One row of IR_OPS, as the back ends read it. */
typedef struct ir_opinfo {
    const char *name;          /* .sg node type, NULL for internal ops   */
    const char *ports[4];      /* input port names, in arg order          */
    int         nargs;         /* 4 for CONSTRUCT means "up to 4"         */
    unsigned    flags;         /* IR_COMMUTATIVE | IR_COMPONENTWISE | …   */
    const char *glsl;          /* GLSL form: "mix($0, $1, $2)"            */
    /* Result type for operand types, or IR_T_ERROR.  The front end's type
     * checker calls this too, so the two cannot disagree. */
    ir_type   (*type)(const ir_type *args, int nargs);
    /* The op's meaning, written once beside its type rule and GLSL and
     * read by ir_eval, ir_interval and opt_fold.  `atype[i]` is operand
     * i's type, a[4 * i + c] its component c; `out` receives the result's
     * components.  NULL for the leaves and SAMPLE, whose values come from
     * the evaluator's environment. */
    void      (*eval)(const struct ir_node *n, const ir_type *atype,
                      const double *a, double out[4]);
    void      (*interval)(const struct ir_node *n, const ir_type *atype,
                          const ir_iv *a, ir_iv *out);
    /* Componentwise ops (CW rows): the scalar functions `eval` and
     * `interval` apply per component; NULL otherwise. */
    double    (*scalar_eval)(const double *x);
    ir_iv     (*scalar_interval)(const ir_iv *x);
    unsigned      finite;      /* IR_FIN_*                                */
    ir_fp32_class fp32;        /* fp32 error class                        */
    int           cost;        /* cost units per component (see IR_OPS)   */
    /* The deriv column is not here: ir_deriv_rule (ir_derive_rules.c). */
} ir_opinfo;

const ir_opinfo *ir_opinfo_get(ir_op op);
/* The op whose .sg node type is `name`, or -1. */
int              ir_op_by_name(const char *name);

/* ---- the IR ------------------------------------------------------------ */

typedef struct ir_ref { uint32_t id; } ir_ref;
#define IR_NONE ((ir_ref){0})
static inline bool ir_ref_eq(ir_ref a, ir_ref b) { return a.id == b.id; }
static inline bool ir_ref_ok(ir_ref a) { return a.id != 0; }

typedef struct ir_node {
    uint8_t  op;       /* ir_op                                   */
    uint8_t  type;     /* ir_type of the result                   */
    uint8_t  nargs;
    uint8_t  pad;
    uint32_t imm;      /* INPUT/PARAM/TEXTURE/PAINTED index, SWIZZLE */
    ir_ref   arg[4];
    double   val[4];   /* CONST components (unused ones are 0)    */
} ir_node;

/* A runtime uniform.  Material params are qualified ("cliff.wetness"). */
typedef struct ir_param {
    char   *name;
    ir_type type;
    double  def[4];    /* default value                                  */
    double  lo, hi;    /* range the runtime allows; the interval analysis
                          is sound over it.  lo == hi == def[0] if fixed */
} ir_param;

/* Sampler state and its names, one table each: graph files, dumps, the
 * pack manifest and generated comments all spell them so. */
#define IR_FILTERS(X) X(LINEAR, "linear") X(NEAREST, "nearest")
#define IR_WRAPS(X)   X(REPEAT, "repeat") X(CLAMP, "clamp") X(MIRROR, "mirror")
typedef enum ir_filter {
#define X(id, name) IR_FILTER_##id,
    IR_FILTERS(X)
#undef X
} ir_filter;
typedef enum ir_wrap {
#define X(id, name) IR_WRAP_##id,
    IR_WRAPS(X)
#undef X
} ir_wrap;
const char *ir_filter_name(ir_filter f);
const char *ir_wrap_name(ir_wrap w);
/* Texel index i of a side of n texels under wrap mode w (the sampler's
 * addressing; CPU twins of texture reads use it). */
int ir_wrap_index(int i, int n, ir_wrap w);
int         ir_filter_by_name(const char *name);   /* -1 if unknown */
int         ir_wrap_by_name(const char *name);     /* -1 if unknown */

/* A texture resource: a file and its sampler state.  Two with the same
 * file and state are the same resource (ir_texture_same: opt_dedup merges
 * them, the pack layout binds them once). */
typedef struct ir_texture {
    char     *file;     /* path as resolved by the front end (relative to
                           the graph file that named it)                   */
    ir_filter filter;   /* mag/min filter                                   */
    ir_filter mip;      /* mipmap filter                                    */
    ir_wrap   wrap;
    bool      srgb;     /* colour texture (sRGB) or data (linear)           */
    double    lo, hi;   /* bounds of every texel channel, for intervals
                           (0..1 for UNORM files)                           */
} ir_texture;

/* A painted mask raster named by the scene (OP_PAINTED reads it, 0..1).
 * The names "vector.NAME" and "vector.NAME.across" are the scene's
 * spline or polygon NAME instead (compiler/vector.c: its mask and its
 * distance across, both 0..1), read through the same leaf so that every
 * pass treats them alike; the composite reads them with
 * splat_vector_mask / splat_vector_across (abi.c), not splat_painted. */
typedef struct ir_painted {
    char *name;
} ir_painted;

/* A named result: a material output ("cliff.mask") or a test root. */
typedef struct ir_root {
    char  *name;
    ir_ref ref;
} ir_root;

typedef struct ir {
    ir_node   *nodes;     /* nodes[0] is the unused "none" node */
    uint32_t   nnodes, capnodes;
    uint32_t  *table;     /* hash-cons table: node ids, 0 = empty */
    uint32_t   captable;
    ir_param  *params;     int nparams, capparams;
    ir_texture *textures;  int ntextures, captextures;
    ir_painted *painted;   int npainted, cappainted;
    ir_root   *roots;      int nroots, caproots;
} ir;

void ir_init(ir *ir);
void ir_free(ir *ir);

static inline const ir_node *ir_get(const ir *ir, ir_ref r) { return &ir->nodes[r.id]; }
static inline ir_type ir_typeof(const ir *ir, ir_ref r) { return (ir_type)ir->nodes[r.id].type; }

/* Builder.  Each returns the hash-consed node; operand types must satisfy
 * the op's type rule (a violation is a compiler bug: assert).  Builders do
 * no folding: that is opt_fold's job, so tests see the pass work. */
ir_ref ir_const(ir *ir, ir_type t, const double *v);
ir_ref ir_constf(ir *ir, double v);
ir_ref ir_input(ir *ir, ir_input_kind which);
ir_ref ir_param_ref(ir *ir, int param);
ir_ref ir_texture_ref(ir *ir, int texture);
ir_ref ir_painted_ref(ir *ir, int painted);
ir_ref ir_op1(ir *ir, ir_op op, ir_ref a);
ir_ref ir_op2(ir *ir, ir_op op, ir_ref a, ir_ref b);
ir_ref ir_op3(ir *ir, ir_op op, ir_ref a, ir_ref b, ir_ref c);
ir_ref ir_opn(ir *ir, ir_op op, const ir_ref *args, int nargs);
ir_ref ir_splat(ir *ir, ir_ref a, ir_type to);          /* no-op if same type */
ir_ref ir_swizzle(ir *ir, ir_ref a, const char *comps); /* "xyz", "rgb", "r"  */
ir_ref ir_construct(ir *ir, ir_type t, const ir_ref *args, int nargs);
/* Any node, given fully (used by passes that rebuild). */
ir_ref ir_node_add(ir *ir, const ir_node *n);
/* The existing node equal to `n` (after canonicalising it), or IR_NONE. */
ir_ref ir_lookup(const ir *ir, const ir_node *n);

/* Tables.  add_* interns: same key returns the same index. */
int  ir_add_param(ir *ir, const ir_param *p);     /* key: name            */
int  ir_add_texture(ir *ir, const ir_texture *t); /* appends (no interning:
                                                     opt_dedup merges)    */
int  ir_add_painted(ir *ir, const char *name);    /* key: name            */
/* The texture identity: same file and sampler state (filter, mip, wrap,
 * sRGB).  The value bounds follow from the file. */
bool ir_texture_same(const ir_texture *a, const ir_texture *b);
void ir_set_root(ir *ir, const char *name, ir_ref r); /* add or replace   */
ir_ref ir_find_root(const ir *ir, const char *name);  /* IR_NONE if absent */

/* Cost (IR_OPS' cost column, in its units): of node `r` alone, and of
 * every node under `roots` counted once (a shared subtree is paid once,
 * as the emitter writes it once). */
int  ir_node_cost(const ir *ir, ir_ref r);
long ir_cost(const ir *ir, const ir_ref *roots, int nroots);

/* Copy the subgraph under `r` of `src` into `dst` (params, textures and
 * painted masks re-interned), returning its ref in dst.  Composites are
 * built by importing each material's IR into one shared ir. */
typedef struct ir_import_map ir_import_map;  /* opaque memo, per src */
ir_import_map *ir_import_begin(ir *dst, const ir *src);
ir_ref         ir_import(ir_import_map *m, ir_ref r);
void           ir_import_end(ir_import_map *m);
/* A fresh `dst` holding `src`'s roots (and what they reach), same names. */
void           ir_clone(ir *dst, const ir *src);

/* ---- passes (opt_*.c) -------------------------------------------------- */

/* Each pass rewrites the ir in place (rebuilding its node array from the
 * roots) and returns whether anything changed. */
bool opt_fold(ir *ir);   /* constant folding and algebraic identities */
bool opt_dce(ir *ir);    /* drop nodes no root reaches                */
bool opt_dedup(ir *ir);  /* merge textures with equal file + sampler  */

/* The passes' shared step (opt.c): rebuild `ir` from its roots.  Each
 * node a root reaches is visited in id order with its operands already
 * renamed into the new node array; `fn` returns its replacement there
 * (ir_node_add(dst, n) keeps it; NULL fn keeps every node).  Unreached
 * nodes disappear; tables are kept.  Returns whether the node array or a
 * root changed. */
typedef ir_ref (*ir_rewrite_fn)(ir *dst, const ir_node *n, void *user);
bool ir_rebuild(ir *ir, ir_rewrite_fn fn, void *user);

/* Every transformation of an ir is a pass of this table, so each is
 * named and the validator runs after each (when built with
 * SPLAT_VALIDATE_IR, as every build of this project is).  The pipeline's
 * passes (dedup, fold, dce: `pipeline`) run to a fixed point in
 * ir_optimize; the others run on their own through ir_pass_run:
 * differentiate (explicit texture gradients) and pin (constants over a
 * region: `arg` is its const ir_ienv *).  run returns progress. */
typedef bool (*ir_pass_fn)(ir *ir, const void *arg);
typedef struct ir_pass { const char *name; ir_pass_fn run; bool pipeline; } ir_pass;
extern const ir_pass ir_passes[];   /* the pipeline's in order, then the rest; NULL-ended */
const ir_pass *ir_pass_find(const char *name);   /* NULL if none */
/* Run one pass by name (a name not in the table is a compiler bug). */
bool ir_pass_run(ir *ir, const char *name, const void *arg);

/* Run the pipeline's passes to a fixed point; with `stop_after` (a pass
 * name) stop after that pass's first run (for `splatc dump --after`). */
void ir_optimize(ir *ir, const char *stop_after);

/* ---- derivatives (ir_differentiate.c) ---------------------------------- */

/* The pass: every SAMPLE(tex, uv) becomes SAMPLE_GRAD(tex, uv, duv/dx,
 * duv/dy), the gradients built as IR by forward-mode differentiation with
 * the op table's rules (IR_OPS' deriv column) from DINPUT leaves.  For
 * shaders without implicit derivatives (the compute stage).  Returns
 * progress.  Run ir_optimize after it to fold the zeros away. */
bool   ir_differentiate(ir *ir);
/* The derivative of `r` along `axis` (0: d/dx, 1: d/dy) as a node of `ir`
 * (a constant 0 if it is zero), built the same way (for tests). */
ir_ref ir_derivative(ir *ir, ir_ref r, int axis);
/* The footprint of `r` over one pixel, |dr/dx| + |dr/dy| (GLSL's fwidth,
 * per component), as nodes of `ir`: .sg's fwidth node.  Unlike texture
 * gradients it follows terrain.slope and terrain.normal too (their
 * DINPUT leaves).  A constant 0 if r does not move. */
ir_ref ir_footprint(ir *ir, ir_ref r);

/* What the rules build with: the ir, the axis, and arithmetic that reads
 * IR_NONE as zero and splats a float operand to the other's width. */
struct ir_dctx {
    ir       *ir;
    int       axis;
    uint32_t *memo[2];  /* per axis, per node: derivative id + 1, or 0      */
    uint32_t  cap;      /* entries of each memo                            */
    bool      curvature; /* slope and normal move too (ir_footprint)       */
};
ir_ref ir_d_add(ir_dctx *c, ir_ref a, ir_ref b);   /* a + b, NONE = 0     */
ir_ref ir_d_sub(ir_dctx *c, ir_ref a, ir_ref b);   /* a - b               */
ir_ref ir_d_mul(ir_dctx *c, ir_ref a, ir_ref b);   /* a * b (NONE if
                                                       either is NONE)    */
ir_ref ir_d_div(ir_dctx *c, ir_ref a, ir_ref b);   /* a / b (NONE if a is) */
ir_ref ir_d_num(ir_dctx *c, ir_type t, double v);   /* constant v of type t */
ir_ref ir_d_zero(ir_dctx *c, ir_ref d, ir_type t);  /* d, or 0 if NONE     */
/* IR_OPS' deriv column (ir_derive_rules.c): the derivative of node `self`
 * (a copy in `n`) along the context's screen axis, built in the context's
 * ir from its operands and their derivatives d[i] (IR_NONE: zero); IR_NONE
 * for a zero derivative.  ir_deriv_rule returns NULL where it is always 0
 * (the D0 rows). */
typedef ir_ref (*ir_deriv_fn)(ir_dctx *c, const ir_node *n, ir_ref self, const ir_ref *d);
ir_deriv_fn ir_deriv_rule(ir_op op);

/* ---- validator (ir_validate.c) ----------------------------------------- */

/* Checks the invariants (operand ids in range and earlier than the node,
 * types satisfy the op's rule, hash table consistent, commutative operands
 * canonical, roots valid).  On failure prints "file:line: #cond (node N)"
 * messages to `out` (if non-NULL) and returns false. */
bool ir_validate(const ir *ir, FILE *out);

/* ---- dump (ir_dump.c) -------------------------------------------------- */

/* The IR in .sg form, text that reads back in (sg_load_string) and lowers
 * to the same IR: a `material` block per material's roots ("M.mask" …)
 * with its params, `texture` declarations, one `node nN : op { port =
 * nM.out, … }` line per op, terrain input and painted mask in id order,
 * constants as literals, swizzles and splats on the operand, roots as `out`
 * lines; other roots in a `shader dump` block (ir_dump.c says more). */
void ir_dump(const ir *ir, FILE *out);

/* ---- evaluators (ir_eval.c, ir_interval.c) ----------------------------- */

/* Texture lookup for the CPU reference: bilinear, with the resource's wrap
 * and filter; `rgba` receives the texel value.  NULL means "every texture
 * reads (0.5, 0.5, 0.5, 1)". */
typedef void (*ir_sample_fn)(void *user, int texture, double u, double v,
                             double rgba[4]);

/* The same with SAMPLE_GRAD's gradients (duv/dx, duv/dy), for a reference
 * that filters as the GPU does (the far atlas bake, far_atlas.c). */
typedef void (*ir_sample_grad_fn)(void *user, int texture, const double uv[2],
                                  const double dx[2], const double dy[2], double rgba[4]);

typedef struct ir_env {
    double height, slope;          /* terrain inputs at the sample point */
    double normal[3], position[3], uv[2];
    double view_distance, destruction;
    const double *params;          /* 4 doubles per param; NULL = defaults */
    const double *painted;         /* 1 double per painted mask; NULL = 0 */
    ir_sample_fn sample; void *sample_user;
    double view_direction[3];      /* unit vector from the point to the
                                      camera, terrain-local; (0, 0, 0)
                                      reads as (0, 1, 0), straight down  */
    double cavity;                 /* terrain.cavity: the heightfield's
                                      mean at 4 diagonal taps 2 texels
                                      away minus the height here, metres
                                      (splat_terrain_cavity)             */
    double shading_lod;            /* view.shading_lod: 1 where the renderer
                                      draws the CPU shading LOD (abi.h
                                      SPLAT_SPEC_LOD), else 0; the CPU
                                      reference and the far-atlas bake
                                      are the full shading: 0            */
    double d_input[2][IR_IN_COUNT][4]; /* DINPUT leaves: screen-space
                                      derivative of each input, per axis
                                      (d/dx, d/dy); 0 when unset          */
    ir_sample_grad_fn sample_grad; /* non-NULL: SAMPLE_GRAD calls it (with
                                      sample_user) instead of `sample`    */
} ir_env;

/* Double-precision reference value of `r` (w = ir_type_width components). */
void ir_eval(const ir *ir, ir_ref r, const ir_env *env, double out[4]);
/* One step of ir_eval: node `id`'s value at `env` (not NULL) into
 * vals[id], from its operands' values already in `vals` (4 per node,
 * indexed by id).  For walks that inspect or perturb every node's value
 * (the harness's fp32 sensitivity analysis, tests/harness/harness_ref.c). */
void ir_eval_node(const ir *ir, uint32_t id, const ir_env *env, double (*vals)[4]);

typedef struct ir_iv { double lo, hi; } ir_iv;

/* Input regions for the interval evaluator: every input lies in its
 * interval (component-wise for vectors).  view.direction has no field: the
 * camera is not part of a terrain region, so its bounds are always
 * [-1, 1] per component (a unit vector). */
typedef struct ir_ienv {
    ir_iv height, slope, normal[3], position[3], uv[2];
    ir_iv view_distance, destruction;
    const ir_iv *params;           /* 1 per param; NULL = [lo, hi] of each */
    const ir_iv *painted;          /* 1 per painted mask; NULL = [0, 1]    */
} ir_ienv;

/* One row of IR_INPUTS, as the evaluators, the emitter and the CLI read
 * it.  The env slots are byte offsets of the input's first component. */
typedef struct ir_input_info {
    const char *name;          /* "terrain.height"                        */
    const char *glsl;          /* "splat_height()"                        */
    const char *key;           /* `splatc eval --at` key: "height"        */
    ir_type     type;
    size_t      env_off;       /* offsetof(ir_env, field)                 */
    long        ienv_off;      /* offsetof(ir_ienv, field), -1: none      */
    ir_iv       domain[4];     /* every value it can take, per component  */
    bool        hoist;         /* composites read it once into a local    */
    const char *local;         /* that local's name: "in_" + ev field     */
    const char *dglsl;         /* derivative accessor "splat_d_height"
                                  (takes the axis), NULL: derivative 0    */
} ir_input_info;

const ir_input_info *ir_input_get(ir_input_kind which);
/* The input whose .sg name is `name`, or -1. */
int     ir_input_by_name(const char *name);
/* The input's value slots in `env` (width doubles) and bounds slots in
 * `ienv` (width intervals; NULL where it has none: IV_NONE). */
double *ir_env_slot(ir_env *env, ir_input_kind which);
ir_iv  *ir_ienv_slot(ir_ienv *ienv, ir_input_kind which);
/* Every input of `ienv` set to its domain (params and painted untouched). */
void    ir_ienv_domain(ir_ienv *ienv);

/* Sound bounds: for every input point in the region, ir_eval's value lies
 * in out[c] for each component c.  NaN-producing cases widen to
 * [-inf, +inf]. */
void ir_interval(const ir *ir, ir_ref r, const ir_ienv *env, ir_iv out[4]);
/* The same for every node at once: vals[id] (4 per node, ir->nnodes of
 * them) for each id (compose.c's lazy branches ask about many). */
void ir_interval_all(const ir *ir, const ir_ienv *env, ir_iv (*vals)[4]);
/* A pass outside the pipeline (it needs a region): every value whose
 * bounds over `env` are one finite point becomes that constant
 * (opt_pin.c); run ir_optimize after it.  Distance classes use it
 * (compiler/distance.c). */
bool opt_pin(ir *ir, const ir_ienv *env);

/* ---- GLSL (glsl.c) ----------------------------------------------------- */

/* Growable string. */
typedef struct ir_buf { char *s; size_t len, cap; } ir_buf;
void ir_buf_printf(ir_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* The `n` bytes at `s` appended (kept NUL-terminated). */
void ir_buf_put(ir_buf *b, const char *s, size_t n);
void ir_buf_free(ir_buf *b);

/* The emitter writes each value once, operands first, as `T vN = …;`
 * (trivial leaves are inlined).  Scopes follow GLSL blocks: a value first
 * emitted inside a scope is forgotten when the scope is popped, so a
 * composite can place shared values at the block that dominates their uses
 * (the caller decides placement; see compose.c).
 *
 * The caller declares the uniforms and samplers and says how the IR's
 * tables read in GLSL: names.param[i] is an expression of the param's type
 * ("u_params.cliff_wetness"), names.texture[i] a sampler2D name,
 * names.painted[i] a float expression.  Inputs read through the ABI
 * prelude's functions (abi.h: splat_height(), splat_normal(), …). */
typedef struct glsl_names {
    const char *const *param;
    const char *const *texture;
    /* NULL: each texture is a sampler2D; else texture i is layer
     * texture_layer[i] of the sampler2DArray texture[i] names, and its
     * samples read vec3(uv, layer) (the pack's texture arrays, abi.h) */
    const int *texture_layer;
    const char *const *painted;
    /* NULL, or per node id: a complete GLSL expression emitted for that
     * node instead of its op, reading only the operands it names as $k
     * (precision.c's camera-relative rewrites). */
    const char *const *override;
} glsl_names;

typedef struct glsl_emitter glsl_emitter;
glsl_emitter *glsl_emitter_new(const ir *ir, const glsl_names *names, ir_buf *out);
void          glsl_emitter_free(glsl_emitter *e);
/* Emit `r` (and whatever it needs that is not yet visible) at the current
 * point with `indent`; return a GLSL expression for it (valid until the
 * enclosing scope is popped; owned by the emitter). */
const char   *glsl_value(glsl_emitter *e, ir_ref r, const char *indent);
void          glsl_scope_push(glsl_emitter *e);
void          glsl_scope_pop(glsl_emitter *e);
/* Values of op `op` emitted in the innermost open scope itself (the whole
 * shader's outermost level when none is open): e.g. the texture samples a
 * block takes, for the counting variant. */
int           glsl_scope_count(const glsl_emitter *e, ir_op op);
/* From now on (until the current scope is popped) `r` reads as the GLSL
 * variable `name`, which the caller has declared: a value computed inside
 * a block the caller closed (compose.c's lazy branches). */
void          glsl_bind(glsl_emitter *e, ir_ref r, const char *name);
/* While `decls` is non-NULL, each value is declared there (once, at one
 * indent, no initialiser) and assigned where it is computed: values stay
 * visible past the block they were computed in (compose.c's long chains). */
void          glsl_hoist(glsl_emitter *e, ir_buf *decls);
/* Where the emitter writes from now on. */
void          glsl_set_out(glsl_emitter *e, ir_buf *out);

/* GLSL literal for a constant of type t ("vec3(0.5, 0.5, 0.5)"), exact
 * enough to round-trip a float. */
void glsl_literal(ir_buf *b, ir_type t, const double *v);

#endif
