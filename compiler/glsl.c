/* glsl.c — the GLSL emitter (see ir.h): each value once, operands first,
 * as `T vN = …;`, with the op table's GLSL forms.  Trivial leaves
 * (constants, inputs, params, painted masks, samplers) are written in
 * place.  Values emitted inside a scope are forgotten when it is popped.
 * The ir must not grow while an emitter on it lives (asserted).
 */
#include "ir.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static void *xalloc(size_t n)
{
    void *p = calloc(1, n ? n : 1);
    if (!p) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    return p;
}

static void *xgrow(void *p, size_t n)
{
    p = realloc(p, n ? n : 1);
    if (!p) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    return p;
}

/* ---- literals ----------------------------------------------------------- */

/* A float literal that reads back to the same float (the value is rounded
 * to float first: that is what the shader computes with). */
static void float_literal(ir_buf *b, double v)
{
    float f = (float)v;
    if (isnan(f)) {
        ir_buf_printf(b, "uintBitsToFloat(0x7fc00000u)");
        return;
    }
    if (isinf(f)) {
        ir_buf_printf(b, "uintBitsToFloat(%s)", f < 0 ? "0xff800000u" : "0x7f800000u");
        return;
    }
    char s[32];
    snprintf(s, sizeof s, "%.9g", (double)f);
    ir_buf_printf(b, "%s%s", s, strpbrk(s, ".e") ? "" : ".0");
}

void glsl_literal(ir_buf *b, ir_type t, const double *v)
{
    int w = ir_type_width(t);
    assert(w > 0);
    if (w == 1) {
        float_literal(b, v[0]);
        return;
    }
    bool same = true;
    for (int c = 1; c < w; c++)
        same = same && (float)v[c] == (float)v[0];
    ir_buf_printf(b, "%s(", ir_type_name(t));
    for (int c = 0; c < (same ? 1 : w); c++) {
        if (c)
            ir_buf_printf(b, ", ");
        float_literal(b, v[c]);
    }
    ir_buf_printf(b, ")");
}

/* ---- the emitter -------------------------------------------------------- */

struct glsl_emitter {
    const ir  *ir;
    uint32_t   nnodes;    /* ir->nnodes when created: the ir must not grow */
    glsl_names names;
    ir_buf    *out;
    char     **expr;      /* per node: its GLSL expression once known      */
    int       *level;     /* per node: scope level it was emitted at, -1   */
    uint32_t  *emitted;   /* ids in emission order (popped with scopes)    */
    int        nemitted, capemitted;
    int       *scope_mark; /* nemitted at each push                        */
    int        nscopes, capscopes;
    uint32_t  *work;      /* scratch for glsl_value                        */
    uint8_t   *seen;
    uint8_t   *bound;     /* per node: its expression came from glsl_bind  */
    ir_buf    *decls;     /* glsl_hoist: where values are declared, or NULL */
    uint8_t   *declared;  /* per node: declared there already              */
};

glsl_emitter *glsl_emitter_new(const ir *ir, const glsl_names *names, ir_buf *out)
{
    glsl_emitter *e = xalloc(sizeof *e);
    e->ir = ir;
    e->nnodes = ir->nnodes;
    if (names)
        e->names = *names;
    e->out = out;
    e->expr = xalloc(sizeof(char *) * ir->nnodes);
    e->level = xalloc(sizeof(int) * ir->nnodes);
    for (uint32_t i = 0; i < ir->nnodes; i++)
        e->level[i] = -1;
    e->work = xalloc(sizeof(uint32_t) * ir->nnodes);
    e->seen = xalloc(ir->nnodes);
    e->bound = xalloc(ir->nnodes);
    return e;
}

void glsl_emitter_free(glsl_emitter *e)
{
    if (!e)
        return;
    for (uint32_t i = 0; i < e->nnodes; i++)
        free(e->expr[i]);
    free(e->expr);
    free(e->level);
    free(e->emitted);
    free(e->scope_mark);
    free(e->work);
    free(e->seen);
    free(e->bound);
    free(e->declared);
    free(e);
}

void glsl_scope_push(glsl_emitter *e)
{
    if (e->nscopes == e->capscopes) {
        e->capscopes = e->capscopes ? 2 * e->capscopes : 8;
        e->scope_mark = xgrow(e->scope_mark, sizeof(int) * (size_t)e->capscopes);
    }
    e->scope_mark[e->nscopes++] = e->nemitted;
}

void glsl_scope_pop(glsl_emitter *e)
{
    assert(e->nscopes > 0);
    int mark = e->scope_mark[--e->nscopes];
    while (e->nemitted > mark) {
        uint32_t id = e->emitted[--e->nemitted];
        e->level[id] = -1;
        e->bound[id] = 0;
        free(e->expr[id]);
        e->expr[id] = NULL;
    }
}

int glsl_scope_count(const glsl_emitter *e, ir_op op)
{
    int from = e->nscopes ? e->scope_mark[e->nscopes - 1] : 0, n = 0;
    for (int i = from; i < e->nemitted; i++)
        n += e->ir->nodes[e->emitted[i]].op == op && !e->bound[e->emitted[i]];
    return n;
}

static void remember(glsl_emitter *e, uint32_t id, char *expr)
{
    e->expr[id] = expr;
    e->level[id] = e->nscopes;
    if (e->nemitted == e->capemitted) {
        e->capemitted = e->capemitted ? 2 * e->capemitted : 64;
        e->emitted = xgrow(e->emitted, sizeof(uint32_t) * (size_t)e->capemitted);
    }
    e->emitted[e->nemitted++] = id;
}

void glsl_set_out(glsl_emitter *e, ir_buf *out)
{
    e->out = out;
}

void glsl_hoist(glsl_emitter *e, ir_buf *decls)
{
    e->decls = decls;
    if (decls && !e->declared)
        e->declared = xalloc(e->nnodes);   /* zeroed */
}

void glsl_bind(glsl_emitter *e, ir_ref r, const char *name)
{
    assert(ir_ref_ok(r) && r.id < e->nnodes && !e->expr[r.id]);
    ir_buf b = {0};
    ir_buf_printf(&b, "%s", name);
    remember(e, r.id, b.s);
    e->bound[r.id] = 1;   /* computed (and counted) inside the closed block */
}

static bool is_leaf(const ir_node *n)
{
    return n->op <= IR_OP_PAINTED || n->op == IR_OP_DINPUT;
}

static char *leaf_expr(glsl_emitter *e, const ir_node *n)
{
    ir_buf b = {0};
    switch (n->op) {
    case IR_OP_CONST: {
        ir_buf lit = {0};
        glsl_literal(&lit, (ir_type)n->type, n->val);
        /* a negative literal as an operand: "x - -1.0" reads badly and
         * "-(-1.0)" must not become "--1.0" */
        ir_buf_printf(&b, lit.s[0] == '-' ? "(%s)" : "%s", lit.s);
        ir_buf_free(&lit);
        break;
    }
    case IR_OP_INPUT:
        ir_buf_printf(&b, "%s", ir_input_get((ir_input_kind)n->imm)->glsl);
        break;
    case IR_OP_PARAM:
        assert(e->names.param && e->names.param[n->imm]);
        ir_buf_printf(&b, "%s", e->names.param[n->imm]);
        break;
    case IR_OP_TEXTURE:
        assert(e->names.texture && e->names.texture[n->imm]);
        ir_buf_printf(&b, "%s", e->names.texture[n->imm]);
        break;
    case IR_OP_DINPUT: {   /* the input row's derivative accessor (abi.c) */
        const char *d = ir_input_get((ir_input_kind)IR_DINPUT_INPUT(n->imm))->dglsl;
        assert(d);
        /* a footprint's normal step (slope, facing: 9 gathers an axis) is 0
         * under the CPU shading LOD; position, height and view steps stay,
         * so far roads and height bands keep their filtering */
        if ((n->imm & IR_DINPUT_FOOTPRINT) && IR_DINPUT_INPUT(n->imm) == IR_IN_NORMAL)
            ir_buf_printf(&b, "splat_fp(%s(%d))", d, IR_DINPUT_AXIS(n->imm));
        else
            ir_buf_printf(&b, "%s(%d)", d, IR_DINPUT_AXIS(n->imm));
        break;
    }
    case IR_OP_PAINTED:
        assert(e->names.painted && e->names.painted[n->imm]);
        ir_buf_printf(&b, "%s", e->names.painted[n->imm]);
        break;
    }
    return b.s;
}

/* The right-hand side of node n (operands already have expressions). */
static void op_expr(glsl_emitter *e, const ir_node *n, ir_buf *b)
{
    uint32_t id = (uint32_t)(n - e->ir->nodes);
    const char *a[4] = {0};
    for (int i = 0; i < n->nargs; i++)
        a[i] = e->expr[n->arg[i].id];
    const char *form = ir_opinfo_get((ir_op)n->op)->glsl;
    char *layered = NULL;   /* vec3(uv, layer) for a texture array */
    if ((n->op == IR_OP_SAMPLE || n->op == IR_OP_SAMPLE_GRAD) && e->names.texture_layer) {
        const ir_node *t = &e->ir->nodes[n->arg[0].id];
        ir_buf l = {0};
        ir_buf_printf(&l, "vec3(%s, %d.0)", a[1], e->names.texture_layer[t->imm]);
        a[1] = layered = l.s;
    }
    if (e->names.override && e->names.override[id]) {
        form = e->names.override[id];   /* its $k read operand k, as below */
        goto substitute;
    }
    const char *tn = ir_type_name((ir_type)n->type);
    int w = ir_type_width((ir_type)n->type);
    switch (n->op) {
    case IR_OP_SPLAT:
        ir_buf_printf(b, "%s(%s)", tn, a[0]);
        return;
    case IR_OP_SWIZZLE:
        if (ir_typeof(e->ir, n->arg[0]) == IR_T_FLOAT) {   /* every comp is x */
            ir_buf_printf(b, w == 1 ? "%s%s" : "%s(%s)", w == 1 ? "" : tn, a[0]);
            return;
        }
        ir_buf_printf(b, "%s.", a[0]);
        for (int i = 0; i < w; i++)
            ir_buf_printf(b, "%c", "xyzw"[IR_SWZ_C(n->imm, i)]);
        return;
    case IR_OP_CONSTRUCT:
        ir_buf_printf(b, "%s(", tn);
        for (int i = 0; i < n->nargs; i++)
            ir_buf_printf(b, "%s%s", i ? ", " : "", a[i]);
        ir_buf_printf(b, ")");
        return;
    case IR_OP_LESS:
        if (w > 1) {
            ir_buf_printf(b, "%s(lessThan(%s, %s))", tn, a[0], a[1]);
            return;
        }
        break;
    case IR_OP_SELECT:
        if (w > 1) {   /* a bvec mix selects without arithmetic (inf-safe) */
            ir_buf_printf(b, "mix(%s, %s, notEqual(%s, %s(0.0)))", a[2], a[1], a[0], tn);
            return;
        }
        break;
    }
    /* the op table's form, $k standing for operand k */
substitute:
    for (const char *p = form; *p;) {
        if (p[0] == '$' && p[1] >= '0' && p[1] <= '3') {
            const char *s = a[p[1] - '0'];
            ir_buf_put(b, s ? s : "(null)", strlen(s ? s : "(null)"));
            p += 2;
        } else {   /* the literal run up to the next operand */
            size_t k = 1;
            while (p[k] && !(p[k] == '$' && p[k + 1] >= '0' && p[k + 1] <= '3'))
                k++;
            ir_buf_put(b, p, k);
            p += k;
        }
    }
    free(layered);
}

static int cmp_id(const void *x, const void *y)
{
    uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
    return (a > b) - (a < b);
}

const char *glsl_value(glsl_emitter *e, ir_ref r, const char *indent)
{
    const ir *ir = e->ir;
    assert(ir_ref_ok(r) && r.id < e->nnodes && ir->nnodes == e->nnodes);
    if (e->expr[r.id])
        return e->expr[r.id];
    /* Collect what is not yet visible (depth first), then emit it in id
     * order, which is topological. */
    int nwork = 0, ntodo = 0;
    uint32_t *todo = xalloc(sizeof(uint32_t) * ir->nnodes);
    e->work[nwork++] = r.id;
    e->seen[r.id] = 1;
    while (nwork > 0) {
        uint32_t id = e->work[--nwork];
        const ir_node *n = &ir->nodes[id];
        if (is_leaf(n)) {
            e->expr[id] = leaf_expr(e, n);   /* leaves stay known for good */
            e->seen[id] = 0;
            continue;
        }
        todo[ntodo++] = id;
        /* an override is written whole: it reads only the operands its
         * $k name */
        const char *ov = e->names.override ? e->names.override[id] : NULL;
        for (int i = 0; i < n->nargs; i++) {
            char ref[3] = {'$', (char)('0' + i), 0};
            if (ov && !strstr(ov, ref))
                continue;
            uint32_t a = n->arg[i].id;
            if (!e->expr[a] && !e->seen[a]) {
                e->seen[a] = 1;
                e->work[nwork++] = a;
            }
        }
    }
    qsort(todo, (size_t)ntodo, sizeof *todo, cmp_id);
    ir_buf rhs = {0};
    for (int k = 0; k < ntodo; k++) {
        uint32_t id = todo[k];
        const ir_node *n = &ir->nodes[id];
        rhs.len = 0;
        op_expr(e, n, &rhs);
        if (e->decls) {   /* glsl_hoist: declared once, there */
            if (!e->declared[id])
                ir_buf_printf(e->decls, "    %s v%u;\n", ir_type_name((ir_type)n->type), id);
            e->declared[id] = 1;
            ir_buf_printf(e->out, "%sv%u = %s;\n", indent ? indent : "", id, rhs.s);
        } else {
            ir_buf_printf(e->out, "%s%s v%u = %s;\n", indent ? indent : "",
                          ir_type_name((ir_type)n->type), id, rhs.s);
        }
        ir_buf name = {0};
        ir_buf_printf(&name, "v%u", id);
        remember(e, id, name.s);
    }
    for (int k = 0; k < ntodo; k++)
        e->seen[todo[k]] = 0;
    e->seen[r.id] = 0;
    ir_buf_free(&rhs);
    free(todo);
    return e->expr[r.id];
}
