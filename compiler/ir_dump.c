/* ir_dump.c — the IR as a graph file, for `splatc dump` and for tests.
 *
 * The text is valid .sg that reads back (sg_load_string) and lowers to the
 * same IR: dumping that again gives the same text (tests/unit/test_dump.c).
 *
 *   texture t0 { file = "graphs/textures/rock.png", filter = linear, mip = linear, wrap = repeat, srgb = false }
 *
 *   material cliff {
 *       param float wetness = 0.2 range 0.0 1.0
 *       node n1 : terrain.slope  # float
 *       node n2 : sub { a = n1.out, b = 0.35 }  # float
 *       node n3 : terrain.position  # vec3
 *       node n4 : mul { a = n3.out.xz, b = vec2(0.125, 0.125) }  # vec2
 *       node n5 : sample { tex = t0, uv = n4.out }  # vec4
 *       node n6 : mix { a = 0.85, b = 0.3, t = wetness }  # float
 *       out mask = n2.out
 *       out albedo = n5.out.xyz
 *       ...
 *   }
 *
 * How each node is written:
 *   - roots "M.mask" … "M.height" (material outputs) become a `material M`
 *     block with `out` lines; its params ("M.wetness") are declared in it
 *     and named by their short name.  Other roots go into a `shader dump`
 *     block with typed outs (params become its inputs, with defaults);
 *   - constants are literals (vec3(…) for vectors), textures top-level
 *     `texture tK` declarations, numbered in order of first use;
 *   - swizzles and splats are written on the operand (`n4.out.xz`,
 *     `n7.out.xxx`, `wetness.x`), nested ones composed;
 *   - terrain inputs, painted masks and every op are `node nK` lines,
 *     numbered 1, 2, … in id order (operands first), each block holding
 *     the nodes its outputs reach, with the type as a comment;
 *   - the operands of a commutative op are written in an order that does
 *     not depend on node ids (nodes by number, then the rest by text), so lowering
 *     the text again, which may create constants in another order, dumps
 *     the same text.
 * Not expressible in .sg (the text then does not read back): CONSTRUCT
 * nodes (written as `construct`; only folding makes them, never from a
 * graph file), non-finite constants (`inf`, `nan`), a texture's value
 * range other than 0..1 (a comment says so).  Texture files are printed as
 * the IR holds them (relative to the current folder).  Deterministic: the
 * same IR always gives the same text.
 */
#include "ir.h"
#include "util.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* The standard material outputs (sg.h's SG_OUTPUTS; the IR does not
 * depend on the front end, so the names are repeated here). */
static const char *const output_names[] = {"mask", "albedo", "normal", "roughness", "height"};
enum { NOUTPUTS = 5 };

/* ---- growable text -------------------------------------------------------- */

typedef struct text { char *s; size_t len, cap; } text;

__attribute__((format(printf, 2, 3)))
static void tx_printf(text *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0)
        abort();
    if (t->len + (size_t)n + 1 > t->cap) {
        t->cap = (t->len + (size_t)n + 1) * 2;
        t->s = xrealloc(t->s, t->cap);
    }
    va_start(ap, fmt);
    vsnprintf(t->s + t->len, t->cap - t->len, fmt, ap);
    va_end(ap);
    t->len += (size_t)n;
}

static void tx_num(text *t, double v)
{
    if (isnan(v)) {
        tx_printf(t, "nan");
        return;
    }
    if (isinf(v)) {
        tx_printf(t, "%s", v < 0 ? "-inf" : "inf");
        return;
    }
    char buf[40];
    /* shortest text that reads back to the same double */
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    tx_printf(t, "%s%s", buf, strpbrk(buf, ".en") ? "" : ".0");
}

static void tx_vec(text *t, ir_type type, const double *v)
{
    int w = ir_type_width(type);
    if (w > 1)
        tx_printf(t, "%s(", ir_type_name(type));
    for (int c = 0; c < w; c++) {
        if (c)
            tx_printf(t, ", ");
        tx_num(t, v[c]);
    }
    if (w > 1)
        tx_printf(t, ")");
}

/* ---- the dump's state ------------------------------------------------------ */

typedef struct dumper {
    const ir *ir;
    uint32_t *number;     /* node id -> its nK number (0: written inline)  */
    int      *tex_name;   /* texture index -> tK (-1: unused)              */
    const char *block;    /* the material being written, or NULL (shader)  */
} dumper;

static bool is_line_node(uint8_t op)
{
    return op != IR_OP_CONST && op != IR_OP_TEXTURE && op != IR_OP_PARAM &&
           op != IR_OP_SWIZZLE && op != IR_OP_SPLAT;
}

/* A param's name inside the current block: its short name in its own
 * material, otherwise the full name with '.' made '_'. */
static void tx_param_name(text *t, const dumper *D, int p)
{
    const char *name = D->ir->params[p].name;
    size_t bl = D->block ? strlen(D->block) : 0;
    if (D->block && !strncmp(name, D->block, bl) && name[bl] == '.') {
        tx_printf(t, "%s", name + bl + 1);
        return;
    }
    for (const char *c = name; *c; c++)
        tx_printf(t, "%c", *c == '.' ? '_' : *c);
}

/* An operand as .sg text: a literal, a texture or param name or nK.out,
 * with the swizzles and splats above it composed into one suffix. */
static void tx_operand(text *t, const dumper *D, ir_ref r)
{
    int comps[4] = {0, 1, 2, 3}, n = 0;  /* n = 0: no swizzle yet */
    const ir_node *nd = ir_get(D->ir, r);
    for (;;) {
        if (nd->op == IR_OP_SWIZZLE) {
            int k = IR_SWZ_N(nd->imm);
            int c[4];
            for (int i = 0; i < (n ? n : k); i++)
                c[i] = IR_SWZ_C(nd->imm, n ? comps[i] : i);
            memcpy(comps, c, sizeof c);
            n = n ? n : k;
        } else if (nd->op == IR_OP_SPLAT) {
            int k = ir_type_width((ir_type)nd->type);
            n = n ? n : k;
            for (int i = 0; i < n; i++)
                comps[i] = 0;
        } else {
            break;
        }
        nd = ir_get(D->ir, nd->arg[0]);
    }
    if (nd->op == IR_OP_CONST) {
        if (!n) {
            tx_vec(t, (ir_type)nd->type, nd->val);
            return;
        }
        double v[4];
        for (int i = 0; i < n; i++)
            v[i] = nd->val[comps[i]];
        tx_vec(t, ir_type_vec(n), v);
        return;
    }
    if (nd->op == IR_OP_TEXTURE)
        tx_printf(t, "t%d", D->tex_name[nd->imm]);
    else if (nd->op == IR_OP_PARAM)
        tx_param_name(t, D, (int)nd->imm);
    else
        tx_printf(t, "n%u.out", D->number[nd - D->ir->nodes]);
    if (n) {
        tx_printf(t, ".");
        for (int i = 0; i < n; i++)
            tx_printf(t, "%c", "xyzw"[comps[i]]);
    }
}

/* The node an operand's text is built on (through swizzles and splats). */
static uint32_t operand_base(const ir *ir, ir_ref r)
{
    while (ir->nodes[r.id].op == IR_OP_SWIZZLE || ir->nodes[r.id].op == IR_OP_SPLAT)
        r = ir->nodes[r.id].arg[0];
    return r.id;
}

static char *operand_string(const dumper *D, ir_ref r)
{
    text t = {0};
    tx_operand(&t, D, r);
    return t.s;
}

static void dump_node(text *t, const dumper *D, uint32_t id)
{
    const ir_node *n = &D->ir->nodes[id];
    const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
    tx_printf(t, "    node n%u : ", D->number[id]);
    if (n->op == IR_OP_INPUT) {
        tx_printf(t, "%s", ir_input_get((ir_input_kind)n->imm)->name);
    } else if (n->op == IR_OP_DINPUT) {   /* terrain.X.dx / .dy (resolve.c) */
        tx_printf(t, "%s.d%c", ir_input_get((ir_input_kind)IR_DINPUT_INPUT(n->imm))->name,
                  "xy"[IR_DINPUT_AXIS(n->imm)]);
    } else if (n->op == IR_OP_PAINTED) {
        tx_printf(t, "painted { mask = \"%s\" }", D->ir->painted[n->imm].name);
    } else {
        static const char *const construct_ports[] = {"x", "y", "z", "w"};
        int order[4] = {0, 1, 2, 3};
        char *arg[4] = {0};
        for (int i = 0; i < n->nargs; i++)
            arg[i] = operand_string(D, n->arg[i]);
        if ((info->flags & IR_COMMUTATIVE) && n->nargs == 2) {
            /* node operands first, by number, then the others by text:
             * independent of the operands' ids */
            uint32_t k0 = D->number[operand_base(D->ir, n->arg[0])];
            uint32_t k1 = D->number[operand_base(D->ir, n->arg[1])];
            k0 = k0 ? k0 : UINT32_MAX;
            k1 = k1 ? k1 : UINT32_MAX;
            if (k1 < k0 || (k1 == k0 && strcmp(arg[1], arg[0]) < 0)) {
                order[0] = 1;
                order[1] = 0;
            }
        }
        /* the derivative pass's ops have no .sg form: named for reading */
        tx_printf(t, "%s {", info->name                       ? info->name
                             : n->op == IR_OP_SAMPLE_GRAD ? "sample_grad"
                             : n->op == IR_OP_LOG2        ? "log2"
                                                          : "construct");
        for (int i = 0; i < n->nargs; i++) {
            const char *port = n->op == IR_OP_CONSTRUCT ? construct_ports[i] : info->ports[i];
            tx_printf(t, "%s %s = %s", i ? "," : "", port, arg[order[i]]);
        }
        tx_printf(t, " }");
        for (int i = 0; i < n->nargs; i++)
            free(arg[i]);
    }
    tx_printf(t, "  # %s\n", ir_type_name((ir_type)n->type));
}

/* The material a root belongs to: "cliff.mask" -> length of "cliff", or -1
 * when the name is not "<material>.<standard output>". */
static int material_prefix(const char *root)
{
    const char *dot = strrchr(root, '.');
    if (!dot || dot == root)
        return -1;
    for (int o = 0; o < NOUTPUTS; o++)
        if (!strcmp(dot + 1, output_names[o]))
            return (int)(dot - root);
    return -1;
}

/* Mark what the roots in `sel` reach. */
static void reach(const ir *ir, const bool *sel, bool *seen)
{
    memset(seen, 0, ir->nnodes * sizeof *seen);
    for (int i = 0; i < ir->nroots; i++)
        if (sel[i] && ir_ref_ok(ir->roots[i].ref))
            seen[ir->roots[i].ref.id] = true;
    for (uint32_t id = ir->nnodes; id-- > 1;)
        if (seen[id])
            for (int a = 0; a < ir->nodes[id].nargs; a++)
                seen[ir->nodes[id].arg[a].id] = true;
}

static void dump_param(text *t, const dumper *D, int p, bool as_input)
{
    const ir_param *pp = &D->ir->params[p];
    tx_printf(t, "    %s %s ", as_input ? "in" : "param", ir_type_name(pp->type));
    tx_param_name(t, D, p);
    tx_printf(t, " = ");
    tx_vec(t, pp->type, pp->def);
    if (!as_input) {
        tx_printf(t, " range ");
        tx_num(t, pp->lo);
        tx_printf(t, " ");
        tx_num(t, pp->hi);
    }
    tx_printf(t, "\n");
}

/* One block: the roots in `sel`, as `material name` or `shader dump`. */
static void dump_block(text *t, dumper *D, const char *name, size_t namelen,
                       const bool *sel, bool *seen)
{
    const ir *ir = D->ir;
    char *block = strndup(name, namelen);
    if (!block)
        abort();
    bool material = namelen > 0;
    D->block = material ? block : NULL;
    reach(ir, sel, seen);
    tx_printf(t, "\n%s %s {\n", material ? "material" : "shader", material ? block : "dump");
    for (int p = 0; p < ir->nparams; p++) {
        const char *pn = ir->params[p].name;
        bool own = material && !strncmp(pn, block, namelen) && pn[namelen] == '.';
        bool used = false;
        for (uint32_t id = 1; id < ir->nnodes && !used; id++)
            used = seen[id] && ir->nodes[id].op == IR_OP_PARAM && ir->nodes[id].imm == (uint32_t)p;
        if (own || used)
            dump_param(t, D, p, !material);
    }
    for (uint32_t id = 1; id < ir->nnodes; id++)
        if (seen[id] && D->number[id])
            dump_node(t, D, id);
    for (int i = 0; i < ir->nroots; i++) {
        if (!sel[i])
            continue;
        const char *out = material ? ir->roots[i].name + namelen + 1 : ir->roots[i].name;
        if (!ir_ref_ok(ir->roots[i].ref)) {
            tx_printf(t, "    # out %s = none\n", out);
            continue;
        }
        if (material) {
            tx_printf(t, "    out %s = ", out);
        } else {
            tx_printf(t, "    out %s ", ir_type_name(ir_typeof(ir, ir->roots[i].ref)));
            for (const char *c = out; *c; c++)
                tx_printf(t, "%c", *c == '.' ? '_' : *c);
            tx_printf(t, " = ");
        }
        tx_operand(t, D, ir->roots[i].ref);
        tx_printf(t, "\n");
    }
    tx_printf(t, "}\n");
    free(block);
    D->block = NULL;
}

void ir_dump(const ir *ir, FILE *out)
{
    dumper D = {.ir = ir};
    int nroots = ir->nroots;
    D.number = calloc((size_t)ir->nnodes + 1, sizeof *D.number);
    D.tex_name = malloc(((size_t)ir->ntextures + 1) * sizeof *D.tex_name);
    bool *all = malloc(((size_t)nroots + 1) * sizeof *all);
    bool *sel = malloc(((size_t)nroots + 1) * sizeof *sel);
    bool *done = calloc((size_t)nroots + 1, sizeof *done);
    bool *seen = malloc(((size_t)ir->nnodes + 1) * sizeof *seen);
    if (!D.number || !D.tex_name || !all || !sel || !done || !seen)
        abort();

    /* numbers for the node lines and texture names, in id order, over
     * everything a root reaches */
    for (int i = 0; i < nroots; i++)
        all[i] = true;
    reach(ir, all, seen);
    uint32_t next = 1;
    int ntex = 0;
    for (int k = 0; k < ir->ntextures; k++)
        D.tex_name[k] = -1;
    for (uint32_t id = 1; id < ir->nnodes; id++) {
        if (!seen[id])
            continue;
        const ir_node *n = &ir->nodes[id];
        if (is_line_node(n->op))
            D.number[id] = next++;
        for (int a = 0; a < n->nargs; a++) {
            const ir_node *m = ir_get(ir, n->arg[a]);
            if (m->op == IR_OP_TEXTURE && D.tex_name[m->imm] < 0)
                D.tex_name[m->imm] = ntex++;
        }
    }

    text t = {0};
    tx_printf(&t, "# splatc dump\n");
    for (int k = 0; k < ntex; k++)
        for (int i = 0; i < ir->ntextures; i++) {
            if (D.tex_name[i] != k)
                continue;
            const ir_texture *tx = &ir->textures[i];
            tx_printf(&t, "texture t%d { file = \"%s\", filter = %s, mip = %s, wrap = %s, srgb = %s }",
                      k, tx->file, ir_filter_name(tx->filter), ir_filter_name(tx->mip),
                      ir_wrap_name(tx->wrap), tx->srgb ? "true" : "false");
            if (tx->lo != 0 || tx->hi != 1) {
                tx_printf(&t, "  # value range ");
                tx_num(&t, tx->lo);
                tx_printf(&t, ":");
                tx_num(&t, tx->hi);
                tx_printf(&t, " (not expressible in .sg)");
            }
            tx_printf(&t, "\n");
        }

    /* one material per prefix, in the order of their first root */
    for (int i = 0; i < nroots; i++) {
        int len = material_prefix(ir->roots[i].name);
        if (done[i] || len < 0)
            continue;
        for (int j = 0; j < nroots; j++) {
            sel[j] = !done[j] && material_prefix(ir->roots[j].name) == len &&
                     !strncmp(ir->roots[j].name, ir->roots[i].name, (size_t)len);
            done[j] |= sel[j];
        }
        dump_block(&t, &D, ir->roots[i].name, (size_t)len, sel, seen);
    }
    /* the other roots */
    bool rest = false;
    for (int j = 0; j < nroots; j++) {
        sel[j] = !done[j];
        rest |= sel[j];
    }
    if (rest)
        dump_block(&t, &D, "", 0, sel, seen);

    if (t.s)
        fwrite(t.s, 1, t.len, out);
    free(t.s);
    free(D.number);
    free(D.tex_name);
    free(all);
    free(sel);
    free(done);
    free(seen);
}
