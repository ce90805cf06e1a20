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
 * port names, its type rule, its GLSL form, its double-precision evaluation
 * and its interval evaluation.  The three back ends (GLSL emitter, CPU
 * reference, interval evaluator) all read that table.
 *
 * Sections below: types, ops, the ir and its builder (ir.c), passes
 * (opt_*.c, driven by ir_optimize in opt.c), validator (ir_validate.c),
 * dump (ir_dump.c), evaluators (ir_eval.c, ir_interval.c), GLSL (glsl.c).
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

/* Terrain and view inputs (OP_INPUT's imm). */
#define IR_INPUTS(X)                                                      \
    X(HEIGHT,        "terrain.height",   IR_T_FLOAT) /* metres, + offset  */ \
    X(SLOPE,         "terrain.slope",    IR_T_FLOAT) /* 1 - normal.y      */ \
    X(NORMAL,        "terrain.normal",   IR_T_VEC3)  /* world, Listing 1  */ \
    X(POSITION,      "terrain.position", IR_T_VEC3)  /* terrain-local m   */ \
    X(UV,            "terrain.uv",       IR_T_VEC2)  /* heightfield 0..1  */ \
    X(VIEW_DISTANCE, "view.distance",    IR_T_FLOAT) /* metres to camera  */ \
    X(DESTRUCTION,   "terrain.destruction", IR_T_FLOAT) /* 0 = untouched */ \
    X(VIEW_DIRECTION, "view.direction",  IR_T_VEC3)  /* unit, to camera   */

/* The type is `enum ir_input` (alias ir_input_kind): the plain name
 * `ir_input` is the builder function below. */
typedef enum ir_input {
#define X(id, name, type) IR_IN_##id,
    IR_INPUTS(X)
#undef X
    IR_IN_COUNT
} ir_input_kind;

/* The op list.  X(id, sg_name, nargs, flags).  The table in ir_ops.c gives
 * each op its ports, type rule, GLSL, eval and interval functions.
 * Ops whose sg_name is NULL are not nodes an artist writes directly. */
#define IR_OPS(X)                                                          \
    /* leaves */                                                           \
    X(CONST,     NULL,         0, 0)  /* val[0..w-1]                    */ \
    X(INPUT,     NULL,         0, 0)  /* imm = ir_input                 */ \
    X(PARAM,     NULL,         0, 0)  /* imm = index into ir.params     */ \
    X(TEXTURE,   NULL,         0, 0)  /* imm = index into ir.textures   */ \
    X(PAINTED,   NULL,         0, 0)  /* imm = index into ir.painted    */ \
    /* shape */                                                            \
    X(SPLAT,     NULL,         1, 0)  /* float -> vecN (type says N)    */ \
    X(SWIZZLE,   NULL,         1, 0)  /* imm = IR_SWZ(n, c0, c1, c2, c3) */\
    X(CONSTRUCT, NULL,         4, 0)  /* vecN from floats (nargs = N)   */ \
    /* texture */                                                          \
    X(SAMPLE,    "sample",     2, 0)  /* (tex, uv) -> vec4              */ \
    /* componentwise arithmetic: operands of one type (lowering splats) */ \
    X(ADD,       "add",        2, IR_COMMUTATIVE | IR_COMPONENTWISE)       \
    X(SUB,       "sub",        2, IR_COMPONENTWISE)                        \
    X(MUL,       "mul",        2, IR_COMMUTATIVE | IR_COMPONENTWISE)       \
    X(DIV,       "div",        2, IR_COMPONENTWISE)                        \
    X(NEG,       "neg",        1, IR_COMPONENTWISE)                        \
    X(MIN,       "min",        2, IR_COMMUTATIVE | IR_COMPONENTWISE)       \
    X(MAX,       "max",        2, IR_COMMUTATIVE | IR_COMPONENTWISE)       \
    X(ABS,       "abs",        1, IR_COMPONENTWISE)                        \
    X(FLOOR,     "floor",      1, IR_COMPONENTWISE)                        \
    X(FRACT,     "fract",      1, IR_COMPONENTWISE)                        \
    X(MOD,       "mod",        2, IR_COMPONENTWISE)                        \
    X(SQRT,      "sqrt",       1, IR_COMPONENTWISE)                        \
    X(POW,       "pow",        2, IR_COMPONENTWISE)                        \
    X(EXP2,      "exp2",       1, IR_COMPONENTWISE)                        \
    X(SIN,       "sin",        1, IR_COMPONENTWISE)                        \
    X(COS,       "cos",        1, IR_COMPONENTWISE)                        \
    X(MIX,       "mix",        3, IR_COMPONENTWISE)  /* a, b, t         */ \
    X(CLAMP,     "clamp",      3, IR_COMPONENTWISE)  /* x, lo, hi       */ \
    X(SATURATE,  "saturate",   1, IR_COMPONENTWISE)                        \
    X(STEP,      "step",       2, IR_COMPONENTWISE)  /* edge, x         */ \
    X(SMOOTHSTEP,"smoothstep", 3, IR_COMPONENTWISE)  /* e0, e1, x       */ \
    X(LESS,      "less",       2, IR_COMPONENTWISE)  /* a < b ? 1 : 0   */ \
    X(SELECT,    "select",     3, IR_COMPONENTWISE)  /* c != 0 ? a : b  */ \
    /* vector */                                                           \
    X(DOT,       "dot",        2, IR_COMMUTATIVE)                          \
    X(LENGTH,    "length",     1, 0)                                       \
    X(NORMALIZE, "normalize",  1, 0)                                       \
    X(CROSS,     "cross",      2, 0)

enum { IR_COMMUTATIVE = 1, IR_COMPONENTWISE = 2 };

typedef enum ir_op {
#define X(id, name, nargs, flags) IR_OP_##id,
    IR_OPS(X)
#undef X
    IR_OP_COUNT
} ir_op;

/* Swizzle immediates: n components, each 0..3 (x y z w). */
#define IR_SWZ(n, a, b, c, d) \
    ((uint32_t)(n) | (uint32_t)(a) << 4 | (uint32_t)(b) << 6 | (uint32_t)(c) << 8 | (uint32_t)(d) << 10)
#define IR_SWZ_N(imm)    ((int)((imm) & 15))
#define IR_SWZ_C(imm, i) ((int)(((imm) >> (4 + 2 * (i))) & 3))

typedef struct ir_iv ir_iv;    /* an interval, defined with the evaluators */
struct ir_node;

typedef struct ir_opinfo {
    const char *name;          /* .sg node type, NULL for internal ops   */
    const char *ports[4];      /* input port names, in arg order          */
    int         nargs;         /* 4 for CONSTRUCT means "up to 4"         */
    unsigned    flags;         /* IR_COMMUTATIVE | IR_COMPONENTWISE       */
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

typedef enum ir_filter { IR_FILTER_LINEAR, IR_FILTER_NEAREST } ir_filter;
typedef enum ir_wrap { IR_WRAP_REPEAT, IR_WRAP_CLAMP, IR_WRAP_MIRROR } ir_wrap;

/* A texture resource: a file and its sampler state.  Two with the same
 * file and state are the same resource (opt_dedup merges them). */
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

/* A painted mask raster named by the scene (OP_PAINTED reads it, 0..1). */
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
void ir_set_root(ir *ir, const char *name, ir_ref r); /* add or replace   */
ir_ref ir_find_root(const ir *ir, const char *name);  /* IR_NONE if absent */

/* Copy the subgraph under `r` of `src` into `dst` (params, textures and
 * painted masks re-interned), returning its ref in dst.  Composites are
 * built by importing each material's IR into one shared ir. */
typedef struct ir_import_map ir_import_map;  /* opaque memo, per src */
ir_import_map *ir_import_begin(ir *dst, const ir *src);
ir_ref         ir_import(ir_import_map *m, ir_ref r);
void           ir_import_end(ir_import_map *m);

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

typedef bool (*ir_pass_fn)(ir *ir);
typedef struct ir_pass { const char *name; ir_pass_fn run; } ir_pass;
extern const ir_pass ir_passes[];   /* in pipeline order, NULL-terminated */

/* Run the passes to a fixed point; with `stop_after` (a pass name) stop
 * after that pass's first run (for `splatc dump --after`).  Validates after
 * every pass when built with SPLAT_VALIDATE_IR (debug builds). */
void ir_optimize(ir *ir, const char *stop_after);

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

/* Sound bounds: for every input point in the region, ir_eval's value lies
 * in out[c] for each component c.  NaN-producing cases widen to
 * [-inf, +inf]. */
void ir_interval(const ir *ir, ir_ref r, const ir_ienv *env, ir_iv out[4]);

/* ---- GLSL (glsl.c) ----------------------------------------------------- */

/* Growable string. */
typedef struct ir_buf { char *s; size_t len, cap; } ir_buf;
void ir_buf_printf(ir_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
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
    const char *const *painted;
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

/* GLSL literal for a constant of type t ("vec3(0.5, 0.5, 0.5)"), exact
 * enough to round-trip a float. */
void glsl_literal(ir_buf *b, ir_type t, const double *v);

#endif
